# pipeline_alloc_tests: daemon::Pipeline's engine and publisher threads do not allocate, counted
# per thread over whole runs (binary output, replay and synthetic streams, linear and
# Gauss-Newton), with a JSON-lines output as the control that the counting sees those threads.
# Included from tests/daemon/CMakeLists.txt.
#
# Links the counting allocator, which replaces the global operator new/delete: only allocation
# tests may go into this binary.
posefair_add_test(pipeline_alloc_tests
  SOURCES pipeline_alloc_tests.cpp ${PROJECT_SOURCE_DIR}/tests/support/counting_allocator.cpp
  LIBS posefair::service posefair::drivers
  LABELS "daemon;threads")
