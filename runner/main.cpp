// psq: the command-line face of PSQ. Every engine exception is caught here and turned into a
// message on stderr and an exit code: 1 bad input, 2 numerical failure, 3 not converged,
// 4 unexpected internal error.

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

#include "engine/core/error.hpp"
#include "engine/scene/key_suggestion.hpp"
#include "runner/commands.hpp"

namespace {

/// Refuses a word where a command is expected (the first argument, and after a command that has
/// commands of its own) that is none of them, naming the nearest: CLI11 would otherwise take
/// `psq promte --help` for the top-level --help and exit 0, and `psq sweep ad` for a missing
/// command.
void require_known_commands(int argc, char** argv, CLI::App& app) {
  CLI::App* parent = &app;
  std::string path = "psq";
  for (int i = 1; i < argc && argv[i][0] != '-'; ++i) {
    const std::vector<CLI::App*> commands = parent->get_subcommands([](CLI::App*) { return true; });
    if (commands.empty()) return;
    std::vector<std::string> names;
    for (const CLI::App* command : commands) names.push_back(command->get_name());
    const std::string given = argv[i];
    const auto found = std::find(names.begin(), names.end(), given);
    if (found == names.end()) {
      const auto nearest = psq::suggest_key(given, names);
      throw psq::InputError(fmt::format(
          "unknown command '{}'{}; `{} --help` lists the commands", given,
          nearest ? fmt::format(" (did you mean '{}'?)", *nearest) : "", path));
    }
    parent = commands[static_cast<std::size_t>(found - names.begin())];
    path += " " + given;
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"PSQ: progressive shell quasistatics"};
  app.set_version_flag("--version", std::string(PSQ_VERSION));
  app.require_subcommand(1);
  std::vector<psq::runner::Command> commands;
  psq::runner::register_sim_command(app, commands);
  psq::runner::register_check_command(app, commands);
  psq::runner::register_ccd_bench_command(app, commands);
  psq::runner::register_sweep_command(app, commands);
  psq::runner::register_status_command(app, commands);
  psq::runner::register_work_command(app, commands);
  psq::runner::register_resume_command(app, commands);
  psq::runner::register_results_command(app, commands);
  psq::runner::register_cancel_command(app, commands);
  psq::runner::register_retry_command(app, commands);
  psq::runner::register_promote_command(app, commands);
  psq::runner::register_report_command(app, commands);
  psq::runner::register_hierarchy_command(app, commands);
  psq::runner::register_slurm_command(app, commands);
  try {
    require_known_commands(argc, argv, app);
    app.parse(argc, argv);
    for (const auto& command : commands)
      if (command.app->parsed()) return command.run();
    return psq::runner::kExitInternalError;
  } catch (const CLI::ParseError& e) {
    // CLI11 prints the message (or the help, exit 0); bad arguments are bad input.
    return app.exit(e) == 0 ? 0 : psq::runner::kExitInputError;
  } catch (const psq::InputError& e) {
    std::cerr << "psq: error: " << e.what() << '\n';
    return psq::runner::kExitInputError;
  } catch (const psq::NumericalError& e) {
    std::cerr << "psq: numerical failure: " << e.what() << '\n';
    return psq::runner::kExitNumericalError;
  } catch (const std::exception& e) {
    std::cerr << "psq: internal error: " << e.what() << '\n';
    return psq::runner::kExitInternalError;
  }
}
