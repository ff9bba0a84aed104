// posefaird: the posefair service (docs/operations.md).
#include <CLI/CLI.hpp>

#include "posefair/core/error.hpp"
#include "posefair/daemon/service.hpp"

int main(int argc, char** argv) {
  CLI::App app{"posefaird: smooths live orientation streams and publishes them over UDP (docs/operations.md)"};
  posefair::daemon::ServiceOptions o;
  std::string config = "/etc/posefair/posefaird.toml";
  app.add_option("-c,--config", config, "configuration file (docs/config.md)")->capture_default_str();
  app.add_flag("--check", o.check_only, "validate the configuration and load its sources, then exit (0 ok, 78 bad)");
  app.add_option("--log-level", o.log_level, "override [logging] level")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.add_option("--log-target", o.log_target, "override [logging] target")->check(CLI::IsMember({"stderr", "journald"}));
  app.set_version_flag("--version", "posefaird 0.1.0");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : posefair::exit_code(posefair::ErrorKind::Usage);
  }
  o.config = config;
  return posefair::daemon::run_service(o);
}
