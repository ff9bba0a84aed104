// A main() for the fuzz targets when they are built without libFuzzer (the normal build, any
// compiler): runs LLVMFuzzerTestOneInput over every file of the corpus folders and files given,
// then over `--random-bytes=N` bytes of seeded random input cut into pieces of random length
// (1 .. 4096 bytes), so the test suite runs every target briefly and deterministically.
// With clang, tools/fuzz.sh builds the same targets against libFuzzer for real fuzzing.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

std::size_t run_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  std::uint64_t random_bytes = 0, seed = 1;
  std::size_t inputs = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--random-bytes=", 0) == 0) {
      random_bytes = std::strtoull(a.c_str() + 15, nullptr, 10);
    } else if (a.rfind("--seed=", 0) == 0) {
      seed = std::strtoull(a.c_str() + 7, nullptr, 10);
    } else if (std::filesystem::is_directory(a)) {
      for (const auto& e : std::filesystem::directory_iterator(a))
        if (e.is_regular_file()) inputs += run_file(e.path());
    } else if (std::filesystem::is_regular_file(a)) {
      inputs += run_file(a);
    } else {
      std::fprintf(stderr, "%s: no such corpus file or folder: %s\n", argv[0], a.c_str());
      return 2;
    }
  }
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> length(1, 4096);
  std::vector<std::uint8_t> buf(4096);
  for (std::uint64_t done = 0; done < random_bytes;) {
    const std::size_t n = std::min<std::uint64_t>(length(rng), random_bytes - done);
    for (std::size_t k = 0; k < n; ++k) buf[k] = static_cast<std::uint8_t>(rng());
    LLVMFuzzerTestOneInput(buf.data(), n);
    done += n;
    ++inputs;
  }
  std::printf("%s: %zu inputs, %llu random bytes, no crash\n", argv[0], inputs, static_cast<unsigned long long>(random_bytes));
  return 0;
}
