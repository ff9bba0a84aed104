#pragma once
// Where the benchmarks find the full recorded data sets, and what they say when one is missing.
// Tests never come here: they read the small excerpts in tests/data. The full sets are not part
// of the repository; they are looked for in $POSEFAIR_DATA, else in ../shared/data from the
// current directory (the project root).
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

namespace posefair::tools {

// $POSEFAIR_DATA when set and not empty, else ../shared/data.
inline std::filesystem::path benchmark_data_dir() {
  const char* env = std::getenv("POSEFAIR_DATA");
  return env != nullptr && *env != '\0' ? std::filesystem::path(env) : std::filesystem::path("../shared/data");
}

// Where a recorded file (relative to the data folder, e.g. "tum/fr2_desk_ORB.txt") comes from.
inline std::string_view recorded_data_source(std::string_view relative) {
  if (relative.starts_with("tum/"))
    return "the TUM RGB-D benchmark (Sturm et al., IROS 2012), as kept in the test data of the evo "
           "trajectory-evaluation tool; licence CC BY 4.0";
  if (relative.starts_with("broad/"))
    return "BROAD, the Berlin Robust Orientation Estimation Assessment Dataset (Laidig, Caruso, Cereatti, Seel, "
           "Data 6(7):72, 2021, doi:10.3390/data6070072), converted from the published MATLAB files to CSV; "
           "licence CC BY 4.0";
  if (relative.starts_with("bvh/Boxing"))
    return "Debian's assimp-testmodels package (BSD-3-Clause)";
  if (relative.starts_with("bvh/"))
    return "the CMU Graphics Lab Motion Capture Database (mocap.cs.cmu.edu), BVH conversion by B. Hahne";
  return "the recorded data sets listed in docs/benchmarks.md";
}

// Where the full sets are looked for, for the end of a message about missing data.
inline std::string where_benchmark_data_is_looked_for() {
  return "The benchmarks read the full recorded data sets, which are not part of the repository, from the "
         "folder named by $POSEFAIR_DATA, or from ../shared/data (relative to the current directory: run "
         "from the project root) when POSEFAIR_DATA is unset. docs/benchmarks.md says where to get them.";
}

// One line per missing file: the path looked at and where that data comes from.
inline std::string missing_file_line(const std::filesystem::path& dir, std::string_view relative) {
  return (dir / relative).string() + " not found; it comes from " + std::string(recorded_data_source(relative)) +
         ".";
}

}  // namespace posefair::tools
