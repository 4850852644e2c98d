#pragma once
// A seam for the crash tests: the environment variable PSQ_TEST_PAUSE_AT names points in the
// worker's work where the process stops itself, so a test can kill it at an exact moment
// (inside a level, between writing a checkpoint and recording it, inside a database write).
//
//   PSQ_TEST_PAUSE_AT=<point>:<n>[:<action>][,<point>:<n>[:<action>]...]
//
// At the n-th pass (1-based) through <point> the process performs <action>: `kill` (default,
// SIGKILL to itself) or `stop` (SIGSTOP: the test kills it, or inspects and continues it).
// Without the variable every hook is a no-op costing one branch.

#include <string_view>

namespace psq::jobs {

/// Counts a pass through the named point and acts when PSQ_TEST_PAUSE_AT asks for it.
/// @throws InputError when PSQ_TEST_PAUSE_AT is malformed (read once, at the first call).
void test_point(std::string_view point);

}  // namespace psq::jobs
