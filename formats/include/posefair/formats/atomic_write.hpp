#pragma once
// Replace a file's contents all at once, so readers (and a crash) see either the old file or
// the complete new one, never a half-written one.
#include <filesystem>
#include <string_view>

namespace posefair::formats {

// Writes `contents` to "<path>.tmp.<pid>" in the same directory, fsyncs it, and renames it over
// `path` (keeping an existing file's permission bits). On any failure the temporary file is
// removed, `path` is untouched, and PoseFileError(path, 0, "<what failed>: <strerror>") is
// thrown. Not meant for two threads of one process writing the same path at once.
void write_file_atomically(const std::filesystem::path& path, std::string_view contents);

}  // namespace posefair::formats
