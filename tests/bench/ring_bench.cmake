# SpscRing against boost::lockfree::spsc_queue. Included from tests/bench/CMakeLists.txt
# (which finds benchmark). Run: build/tests/bench/ring_bench
find_package(Threads REQUIRED)
find_package(Boost REQUIRED)  # header-only: Boost.Lockfree
add_executable(ring_bench ring_bench.cpp)
target_include_directories(ring_bench PRIVATE ${PROJECT_SOURCE_DIR}/daemon/include)
target_link_libraries(ring_bench PRIVATE Boost::headers benchmark::benchmark Threads::Threads posefair_warnings)
