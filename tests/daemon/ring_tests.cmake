# SpscRing, LatencyHistogram, WakeSignal and AdaptiveSpin tests (header-only, daemon/include). Included from
# tests/daemon/CMakeLists.txt.
find_package(Threads REQUIRED)
posefair_add_test(ring_tests
  SOURCES ring_tests.cpp histogram_tests.cpp wake_signal_tests.cpp
  LIBS Threads::Threads
  LABELS "daemon;threads")
target_include_directories(ring_tests PRIVATE ${PROJECT_SOURCE_DIR}/daemon/include)
