#pragma once
// Exit statuses of the posefair tools, from BSD sysexits.h (as gpsd and chrony tools use them).
namespace posefair::tools {
inline constexpr int kExitOk = 0;
inline constexpr int kExitUsage = 64;      // EX_USAGE: bad command line
inline constexpr int kExitDataErr = 65;    // EX_DATAERR: the input file is malformed
inline constexpr int kExitNoInput = 66;    // EX_NOINPUT: the input file cannot be opened
inline constexpr int kExitSoftware = 70;   // EX_SOFTWARE: internal error
inline constexpr int kExitCantCreate = 73; // EX_CANTCREAT: the output cannot be written
inline constexpr int kExitConfig = 78;     // EX_CONFIG: bad configuration
}  // namespace posefair::tools
