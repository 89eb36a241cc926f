// adit keygen --out FILE: a new command key (32 random bytes, HMAC-SHA-256;
// docs/PROTOCOL.md "Authenticated commands") written with mode 0600. The same
// file goes to the payload (lcm.key_file) and to each client that may command
// it (adit --key FILE, the web console, a tablet app).

#include <memory>
#include <string>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/protocol/command_auth.hpp"
#include "commands.hpp"

namespace adit::tools {

void register_keygen_commands(CLI::App& app, int& status) {
  struct Options {
    std::string out;
    bool force = false;
  };
  auto o = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("keygen", "Write a new command key (mode 0600) for signed commands");
  sub->add_option("--out", o->out, "Key file to write")->required();
  sub->add_flag("--force", o->force, "Replace an existing file (atomically)");
  sub->callback([o, &status] {
    const protocol::CommandKey key = protocol::CommandKey::generate();
    protocol::write_key_file(o->out, key, o->force);
    fmt::print("key id {} written to {} (mode 0600)\n", protocol::key_id_hex(key.id()), o->out);
    status = kExitOk;
  });
}

}  // namespace adit::tools
