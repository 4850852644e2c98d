// `psq ccd-bench FILE... [--json]`: runs the additive CCD on benchmark query files (see
// engine/contact/ccd_query_file.hpp) and reports misses, false alarms and the time per query.

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "engine/contact/ccd_query_file.hpp"
#include "engine/core/error.hpp"
#include "runner/commands.hpp"

namespace psq::runner {
namespace {

namespace fs = std::filesystem;

struct CcdBenchOptions {
  std::vector<std::string> paths;
  bool json = false;
  AdditiveCcdSettings settings;
};

/// The .csv files below a directory, in a stable order.
std::vector<fs::path> csv_files_below(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.is_regular_file() && entry.path().extension() == ".csv")
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  if (files.empty())
    throw InputError(located_message(dir.string(), 0, "no .csv query files in this directory"));
  return files;
}

/// Every query file named on the command line, directories expanded recursively.
std::vector<fs::path> query_files(const std::vector<std::string>& paths) {
  std::vector<fs::path> files;
  for (const fs::path path : paths) {
    if (fs::is_directory(path)) {
      const std::vector<fs::path> below = csv_files_below(path);
      files.insert(files.end(), below.begin(), below.end());
    } else if (fs::exists(path)) {
      files.push_back(path);
    } else {
      throw InputError(located_message(path.string(), 0, "no such file or directory"));
    }
  }
  return files;
}

int run_ccd_bench(const CcdBenchOptions& options) {
  validate_ccd_settings(options.settings);
  const std::vector<fs::path> files = query_files(options.paths);
  // Kinds first, so that a misplaced file is reported before any work is done.
  std::vector<CcdQueryKind> kinds;
  for (const fs::path& file : files) kinds.push_back(ccd_query_kind(file));

  CcdTally total;
  std::chrono::steady_clock::duration ccd_time{};
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::vector<CcdQuery> queries = read_ccd_queries(files[i]);
    const auto start = std::chrono::steady_clock::now();  // times the CCD only, not the reading
    total += tally_ccd_queries(queries, kinds[i], options.settings);
    ccd_time += std::chrono::steady_clock::now() - start;
  }
  const double mean_us =
      total.queries == 0
          ? 0.0
          : std::chrono::duration<double, std::micro>(ccd_time).count() / double(total.queries);

  if (options.json) {
    const nlohmann::json result = {{"queries", total.queries},
                                   {"false_negatives", total.false_negatives},
                                   {"false_positives", total.false_positives},
                                   {"mean_us", mean_us}};
    std::cout << result.dump() << '\n';
  } else {
    std::cout << fmt::format(
        "queries: {}\nfalse negatives: {}\nfalse positives: {}\nmean time per query: {:.3f} us\n",
        total.queries, total.false_negatives, total.false_positives, mean_us);
  }
  return 0;
}

}  // namespace

void register_ccd_bench_command(CLI::App& app, std::vector<Command>& commands) {
  auto options = std::make_shared<CcdBenchOptions>();
  CLI::App* command = app.add_subcommand(
      "ccd-bench", "Run the additive CCD on CCD query files and count its misses and false alarms");
  command
      ->add_option("files", options->paths,
                   "Query files or directories (searched recursively for .csv); each file must sit "
                   "in a folder named vertex-face or edge-edge")
      ->required();
  command->add_flag("--json", options->json,
                    "Print one JSON object {queries, false_negatives, false_positives, mean_us}");
  command
      ->add_option("--rescaling", options->settings.rescaling,
                   "Fraction s of the guaranteed-safe time taken per advance, in (0, 1)")
      ->capture_default_str();
  command
      ->add_option("--ratio-bound", options->settings.ratio_bound,
                   "Minimum-distance ratio r kept at the reported time, in (0, 1)")
      ->capture_default_str();
  command
      ->add_option("--max-iterations", options->settings.max_iterations,
                   "Advances per query before it is reported as a collision")
      ->capture_default_str();
  commands.push_back({command, [options] { return run_ccd_bench(*options); }});
}

}  // namespace psq::runner
