#include "bench/bench_options.hpp"

#include <gtest/gtest.h>

#include "support/run_process.hpp"

namespace psq::bench {
namespace {

BenchOptions example_options() {
  return BenchOptions("bench_example",
                      {{"vertices", OptionType::count, "20000", "fine vertices"},
                       {"offset", OptionType::integer, "0", "an offset"},
                       {"scale", OptionType::positive_number, "1", "edge length factor"},
                       {"tolerance", OptionType::positive_number, "", "unset: the scene's"},
                       {"shift", OptionType::number, "-0.5", "any finite number"},
                       {"gradient", OptionType::text, "exact", "exact or held"},
                       {"sizes", OptionType::count_list, "1000,10000", "mesh sizes"},
                       {"scenes", OptionType::text_list, "drape,twist", "scene names"}});
}

/// The message of the OptionError that parsing `arguments` throws ("" if none).
std::string parse_error(const std::vector<std::string>& arguments) {
  BenchOptions options = example_options();
  try {
    options.parse(arguments);
  } catch (const OptionError& e) {
    return e.what();
  }
  return "";
}

TEST(BenchOptions, ValuesAreParsedAndTyped) {
  BenchOptions options = example_options();
  ASSERT_TRUE(options.parse({"--vertices", "500", "--offset", "-3", "--scale", "2.5e-1",
                             "--tolerance", "1e-6", "--gradient", "held", "--sizes", "10,20,30",
                             "--scenes", "cylinder_compress"}));
  EXPECT_EQ(options.integer("vertices"), 500);
  EXPECT_EQ(options.integer("offset"), -3);
  EXPECT_DOUBLE_EQ(options.number("scale"), 0.25);
  EXPECT_DOUBLE_EQ(options.number("tolerance"), 1e-6);
  EXPECT_DOUBLE_EQ(options.number("shift"), -0.5);
  EXPECT_EQ(options.text("gradient"), "held");
  EXPECT_EQ(options.integers("sizes"), (std::vector<int>{10, 20, 30}));
  EXPECT_EQ(options.texts("scenes"), std::vector<std::string>{"cylinder_compress"});
  EXPECT_TRUE(options.given("scale"));
}

TEST(BenchOptions, DefaultsWhenAbsent) {
  BenchOptions options = example_options();
  ASSERT_TRUE(options.parse({"--scale", "3"}));
  EXPECT_EQ(options.integer("vertices"), 20000);
  EXPECT_EQ(options.integer("offset"), 0);
  EXPECT_EQ(options.text("gradient"), "exact");
  EXPECT_EQ(options.integers("sizes"), (std::vector<int>{1000, 10000}));
  EXPECT_EQ(options.texts("scenes"), (std::vector<std::string>{"drape", "twist"}));
  EXPECT_FALSE(options.given("vertices"));
  EXPECT_FALSE(options.given("tolerance"));
  // No default and not given: the program must ask given() first.
  EXPECT_THROW(options.number("tolerance"), std::logic_error);
  // Reading an option as another type, or one it does not declare, is the program's mistake.
  EXPECT_THROW(options.number("vertices"), std::logic_error);
  EXPECT_THROW(options.integer("edges"), std::logic_error);
}

TEST(BenchOptions, HelpIsReported) {
  for (const std::string help : {"--help", "-h"}) {
    BenchOptions options = example_options();
    // Help wins even over an error elsewhere on the line.
    EXPECT_FALSE(options.parse({"--vertices", "abc", help})) << help;
  }
  const std::string usage = example_options().usage();
  EXPECT_NE(usage.find("Usage: bench_example [options]"), std::string::npos) << usage;
  EXPECT_NE(usage.find("--vertices N"), std::string::npos) << usage;
  EXPECT_NE(usage.find("fine vertices (default 20000)"), std::string::npos) << usage;
  EXPECT_NE(usage.find("--sizes N,N,..."), std::string::npos) << usage;
  EXPECT_NE(usage.find("--help"), std::string::npos) << usage;
}

TEST(BenchOptions, UnknownOptionListsTheValidOnes) {
  const std::string message = parse_error({"--vertices", "5", "--vertex", "5"});
  EXPECT_NE(message.find("unknown option '--vertex'"), std::string::npos) << message;
  EXPECT_NE(message.find("--vertices --offset --scale"), std::string::npos) << message;
  EXPECT_NE(parse_error({"drape.toml"}).find("unknown option 'drape.toml'"), std::string::npos);
}

TEST(BenchOptions, MissingValueIsRejected) {
  EXPECT_EQ(parse_error({"--vertices"}), "option --vertices: missing value");
  // The next option is not taken as a value.
  EXPECT_EQ(parse_error({"--gradient", "--vertices", "5"}), "option --gradient: missing value");
}

TEST(BenchOptions, RepeatedOptionIsRejected) {
  EXPECT_EQ(parse_error({"--vertices", "5", "--vertices", "6"}), "option --vertices given twice");
}

TEST(BenchOptions, BadNumbersAreRejectedWithOptionAndValue) {
  EXPECT_EQ(parse_error({"--vertices", "abc"}),
            "option --vertices: expected a positive integer, got 'abc'");
  EXPECT_EQ(parse_error({"--vertices", "12abc"}),
            "option --vertices: expected a positive integer, got '12abc'");
  EXPECT_EQ(parse_error({"--vertices", "0"}),
            "option --vertices: expected a positive integer, got '0'");
  EXPECT_EQ(parse_error({"--vertices", "99999999999"}),
            "option --vertices: expected a positive integer, got '99999999999'");
  EXPECT_EQ(parse_error({"--offset", "1.5"}), "option --offset: expected an integer, got '1.5'");
  EXPECT_EQ(parse_error({"--scale", "1.5x"}),
            "option --scale: expected a positive number, got '1.5x'");
  EXPECT_EQ(parse_error({"--scale", "-1"}), "option --scale: expected a positive number, got '-1'");
  EXPECT_EQ(parse_error({"--scale", "nan"}),
            "option --scale: expected a positive number, got 'nan'");
  EXPECT_EQ(parse_error({"--scale", ""}), "option --scale: expected a positive number, got ''");
  EXPECT_EQ(parse_error({"--shift", "inf"}), "option --shift: expected a finite number, got 'inf'");
  EXPECT_EQ(parse_error({"--shift", "0x"}), "option --shift: expected a finite number, got '0x'");
  EXPECT_EQ(parse_error({"--sizes", "1000,x"}),
            "option --sizes: expected a comma-separated list of positive integers, got '1000,x'");
  EXPECT_EQ(parse_error({"--sizes", "1000,"}),
            "option --sizes: expected a comma-separated list of positive integers, got '1000,'");
  EXPECT_EQ(parse_error({"--scenes", "drape,,twist"}),
            "option --scenes: expected a comma-separated list of names, got 'drape,,twist'");
}

TEST(BenchOptions, BadDefaultIsTheProgramsMistake) {
  EXPECT_THROW(BenchOptions("bench_example", {{"frames", OptionType::count, "ten", "frames"}}),
               OptionError);
}

// The built benchmark: --help and a bad command line end before any benchmark work.
TEST(BenchProgressive, HelpExitsZeroAndBadCommandLineExitsTwo) {
  const test::ProcessResult help = test::run_process(PSQ_BENCH_PROGRESSIVE, {"--help"});
  EXPECT_EQ(help.exit_code, 0) << help.errors;
  EXPECT_NE(help.output.find("Usage: bench_progressive [options]"), std::string::npos)
      << help.output;
  EXPECT_NE(help.output.find("--preview-only"), std::string::npos) << help.output;
  EXPECT_EQ(help.errors, "");

  const test::ProcessResult missing = test::run_process(PSQ_BENCH_PROGRESSIVE, {"--vertices"});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(missing.output, "");
  EXPECT_EQ(missing.errors.rfind("bench_progressive: option --vertices: missing value\nUsage:", 0),
            0u)
      << missing.errors;

  const test::ProcessResult bad = test::run_process(PSQ_BENCH_PROGRESSIVE, {"--frames", "10x"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.errors.find("option --frames: expected a positive integer, got '10x'"),
            std::string::npos)
      << bad.errors;

  // The program's own check of a value, made before any work, ends the same way.
  const test::ProcessResult gradient =
      test::run_process(PSQ_BENCH_PROGRESSIVE, {"--gradient", "exactly"});
  EXPECT_EQ(gradient.exit_code, 2);
  EXPECT_EQ(gradient.output, "");
  EXPECT_NE(gradient.errors.find("option --gradient: expected exact or held, got 'exactly'"),
            std::string::npos)
      << gradient.errors;
}

}  // namespace
}  // namespace psq::bench
