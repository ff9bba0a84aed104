# subscription_attack_tests.cpp: attacks on the subscription port and the control socket
# against the real posefaird, each test in a network namespace of its own (docs/security.md).
# In daemon_e2e_tests (daemon_tests.cmake), which has the same labels and starts the same
# binaries. Reads the daemon's JSON replies with nlohmann/json.
find_package(nlohmann_json 3 REQUIRED)
target_sources(daemon_e2e_tests PRIVATE ${CMAKE_CURRENT_LIST_DIR}/subscription_attack_tests.cpp)
target_link_libraries(daemon_e2e_tests PRIVATE nlohmann_json::nlohmann_json)
