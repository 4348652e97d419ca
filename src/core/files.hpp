// File names and output files. Output files are written whole or not at all, and replace nothing the
// user has unless asked.
#pragma once

#include <string>
#include <string_view>

namespace cellrt {

// Writes `bytes` beside `path` under a temporary name and renames it into place, so an interrupted
// write never leaves a partial file under `path`. Refuses to replace an existing file unless
// `overwrite`. Throws cellrt::Error naming the path on any failure (missing directory, no permission,
// disk full).
void write_file_atomically(const std::string& path, std::string_view bytes, bool overwrite);

// The extension of `path` in lower case, with its dot (".png"), or "" when it has none: formats are
// chosen by extension, whatever its case.
std::string lower_extension(const std::string& path);

}  // namespace cellrt
