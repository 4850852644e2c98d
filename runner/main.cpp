// psq: the command-line face of PSQ. Every engine exception is caught here and turned into a
// message on stderr and an exit code: 1 bad input, 2 numerical failure, 3 not converged,
// 4 unexpected internal error.

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <iostream>

#include "engine/core/error.hpp"
#include "runner/commands.hpp"

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
