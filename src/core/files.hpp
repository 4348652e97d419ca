// File names and output files. Output files are written whole or not at all, and replace nothing the
// user has unless asked.
#pragma once

#include <atomic>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace cellrt {

// Writes `bytes` beside `path` under a temporary name and renames it into place, so an interrupted
// write never leaves a partial file under `path`. Refuses to replace an existing file unless
// `overwrite`, and a folder always. A link to a file is followed: the file is replaced, the link
// kept. A device, a pipe, a socket, and a path under /dev or /proc that leads to a file this process
// holds open for writing (/dev/stdout redirected to a log) are appended to in place, never renamed
// over: renaming would replace the device node or the log. Any other path under /dev or /proc that
// leads to a regular file is that file. A pipe no process reads yet is waited for (set_write_cancel).
// Throws cellrt::Error naming the path on any failure (missing directory, no permission, disk full).
void write_file_atomically(const std::string& path, std::string_view bytes, bool overwrite);

// A flag that ends the wait for a pipe's reader once it is true (the programs' interrupt flag, which
// their signal handlers set): the wait also ends at a signal it sees, but one that came before it
// began would be missed. Null (the default): the wait ends at a signal or a reader only.
void set_write_cancel(const std::atomic<bool>* flag);

// What a program checks before the work whose result goes to `path` (a command-line option's output,
// whose flag is --overwrite): refuses an empty name, a folder, an existing file unless `overwrite`,
// a missing folder, and a file, device or folder this process may not write. Throws cellrt::Error
// naming the path and what to do.
void check_output_file(const std::string& path, bool overwrite);

// What a program checks before the work whose results go into the folder `path` (made when the
// results are written, so that a run that fails leaves no empty folder behind): refuses an empty
// name, a path that names a file, and one that cannot be made (a file on the way, or the nearest
// existing folder not writable). Throws cellrt::Error naming `option` and the path.
void check_output_folder(const std::string& option, const std::string& path);

// Refuses outputs (option, path) that name one file, where the second would replace the first, and
// an output that names one of `inputs` (what, path), which it would replace: "--stats teapot.json
// names the scene teapot.json, which it would replace". Empty paths are not asked for and pass.
void check_distinct_files(const std::vector<std::pair<std::string, std::string>>& outputs,
                          const std::vector<std::pair<std::string, std::string>>& inputs = {});

// The extension of `path` in lower case, with its dot (".png"), or "" when it has none: formats are
// chosen by extension, whatever its case.
std::string lower_extension(const std::string& path);

}  // namespace cellrt
