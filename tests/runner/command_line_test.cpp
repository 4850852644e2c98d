// The psq command line as a whole: an unknown command is an error naming the nearest one, even
// when it comes with --help.

#include <gtest/gtest.h>

#include "support/run_process.hpp"

namespace psq {
namespace {

TEST(CommandLine, AnUnknownCommandWithHelpIsAnErrorSuggestingTheNearest) {
  const auto result = test::run_psq({"promte", "--help"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.errors.find("unknown command 'promte'"), std::string::npos) << result.errors;
  EXPECT_EQ(result.output, "");  // no help text printed as if all were well
}

TEST(CommandLine, ATypoOfACommandSuggestsIt) {
  const auto result = test::run_psq({"reprot", "x"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.errors.find("did you mean 'report'?"), std::string::npos) << result.errors;
}

TEST(CommandLine, AnUnknownCommandOfACommandSuggestsTheNearestOfItsCommands) {
  const auto result = test::run_psq({"sweep", "ad", "x.toml"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.errors.find("unknown command 'ad' (did you mean 'add'?); `psq sweep --help`"),
            std::string::npos)
      << result.errors;
}

TEST(CommandLine, BadArgumentsAreInputErrors) {
  const auto missing = test::run_psq({"sweep"});  // its command missing
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.errors.find("subcommand is required"), std::string::npos) << missing.errors;
  EXPECT_EQ(test::run_psq({"sim", "--levels", "two", "x.toml"}).exit_code, 1);
}

TEST(CommandLine, KnownCommandsAndTopLevelOptionsStillWork) {
  EXPECT_EQ(test::run_psq({"--help"}).exit_code, 0);
  const auto help = test::run_psq({"sim", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("--levels"), std::string::npos);
  // A command with subcommands of its own.
  EXPECT_EQ(test::run_psq({"sweep", "add", "--help"}).exit_code, 0);
}

}  // namespace
}  // namespace psq
