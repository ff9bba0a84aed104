# posefaird's runtime, tested two ways. Included from tests/daemon/CMakeLists.txt.
#
# pipeline_tests: daemon::Pipeline in process (configs parsed from TOML text, a UDP socket of
# the test's own on 127.0.0.1 as the only destination): drop accounting with a deliberately
# slow engine (PipelineHooks) under both overflow policies.
posefair_add_test(pipeline_tests
  SOURCES pipeline_tests.cpp
  LIBS posefair::service posefair::drivers
  LABELS "daemon;network;threads")

# daemon_e2e_tests: the real binaries (posefaird, posefair) as child processes on the
# loopback interface, every wait bounded and every child killed at the end: `posefair fair
# --causal` against the daemon bit for bit, SIGHUP reloads (good and bad), SIGTERM while
# recording and the replay of that recording, a truncated recording, malformed configs, and
# `posefair sub --idle`, a serial device on a pseudo-terminal (a golden replay log, then an
# unplug); and (subscription_attack.cmake) attacks on the subscription port and the control
# socket, each in a network namespace of its own.
posefair_add_test(daemon_e2e_tests
  SOURCES daemon_e2e_tests.cpp
  LIBS posefair::protocol posefair::drivers posefair_replay_log
  LABELS "daemon;network;e2e;threads")
add_dependencies(daemon_e2e_tests posefaird)
posefair_cli_dependency(daemon_e2e_tests)

# status_report_tests.cpp: the counter lines and STATUS= text, with and without a device link;
# in config_tests (CMakeLists.txt here), which has the same label.
# gyro_pairing_tests.cpp: [stream.engine] gyro_stream's matcher, in the same program.
target_sources(config_tests PRIVATE status_report_tests.cpp gyro_pairing_tests.cpp)
target_link_libraries(config_tests PRIVATE posefair::service)
