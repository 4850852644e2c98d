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

/// Refuses a first argument that is neither an option nor a command, naming the nearest command:
/// CLI11 would otherwise take `psq promte --help` for the top-level --help and exit 0.
void require_known_command(int argc, char** argv, CLI::App& app) {
  if (argc < 2 || argv[1][0] == '-') return;
  std::vector<std::string> names;
  for (const CLI::App* command : app.get_subcommands([](CLI::App*) { return true; }))
    names.push_back(command->get_name());
  const std::string given = argv[1];
  if (std::find(names.begin(), names.end(), given) != names.end()) return;
  const auto nearest = psq::suggest_key(given, names);
  throw psq::InputError(fmt::format("unknown command '{}'{}; `psq --help` lists the commands",
                                    given,
                                    nearest ? fmt::format(" (did you mean '{}'?)", *nearest) : ""));
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
  psq::runner::register_report_command(app, commands);
  psq::runner::register_hierarchy_command(app, commands);
  psq::runner::register_slurm_command(app, commands);
  try {
    require_known_command(argc, argv, app);
    app.parse(argc, argv);
    for (const auto& command : commands)
      if (command.app->parsed()) return command.run();
    return psq::runner::kExitInternalError;
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
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
