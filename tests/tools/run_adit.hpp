#pragma once
// Running the built `adit` binary from a test and capturing its output.

#include <sys/wait.h>

#include <cstdio>
#include <string>

#include "shared_data.hpp"
#include "temp_file.hpp"

namespace adit::test {

using namespace std::string_literals;  // "..."s: g++ 12 -Wrestrict misfires on "literal" + std::string

struct EvalRun {
  int status = -1;
  std::string output;  // stdout and stderr together
};

// `adit ARGS` (ARGS quoted for the shell by the caller).
inline EvalRun adit_command(const std::string& args) {
  // Built by appending: g++ 12 -Wrestrict misfires on chains of operator+ here.
  std::string command = "'";
  command += (binary_dir() / "bin" / "adit").string();
  command += "' ";
  command += args;
  command += " 2>&1";
  EvalRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) run.output.append(buffer, n);
  const int raw = ::pclose(pipe);
  run.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return run;
}

inline EvalRun adit_eval(const std::string& args) { return adit_command("eval " + args); }

// A file path quoted for the shell.
inline std::string q(const TempFile& f) { return "'"s + f.path().string() + "'"; }

}  // namespace adit::test
