#pragma once
// Reading a whole input file (scene, sweep, mesh) into memory, with the errors a user can act
// on: each reader then parses the bytes and reports positions inside them.

#include <filesystem>
#include <string>
#include <string_view>

namespace psq {

/// The bytes of `path`. `what` names the kind of file in the messages ("scene file").
/// @throws InputError naming `path`: "no such <what>", "the <what> is not a regular file",
///   "cannot open the <what>: <system reason>" or "read error in the <what>".
std::string read_input_file(const std::filesystem::path& path, std::string_view what);

}  // namespace psq
