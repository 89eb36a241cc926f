// aditd: the real-time LiDAR mapping daemon.

#include <CLI/CLI.hpp>

#include "adit/common/log.hpp"
#include "adit/common/main.hpp"

int main(int argc, char** argv) {
  return adit::guarded_main("aditd", [&]() -> int {
    CLI::App app{"aditd: real-time LiDAR mapping daemon"};
    try {
      app.parse(argc, argv);
    } catch (const CLI::Success& e) {
      return app.exit(e);
    } catch (const CLI::ParseError& e) {
      app.exit(e);
      return adit::kExitBadInput;
    }
    adit::log::init("aditd", adit::log::Level::info);
    return adit::kExitOk;
  });
}
