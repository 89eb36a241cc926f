// Fuzzes the text readers `adit eval` trusts with user files: TUM, KITTI,
// EuRoC CSV, target CSV, the simulator's people tracks and a session's loops
// (summary.json). Bad input must end in adit::InputError, nothing else (no
// crash, no other exception, no sanitizer report).

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "adit/common/error.hpp"
#include "adit/eval/loop_summary_io.hpp"
#include "adit/eval/moving_truth.hpp"
#include "adit/eval/targets_io.hpp"
#include "adit/eval/trajectory_io.hpp"

namespace {

template <typename Read>
void expect_only_input_errors(const std::string& text, Read&& read) {
  std::istringstream in(text);
  try {
    read(in);
  } catch (const adit::InputError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  expect_only_input_errors(text, [](std::istream& in) { adit::eval::read_tum(in, "fuzz.txt"); });
  expect_only_input_errors(text, [](std::istream& in) { adit::eval::read_kitti(in, "fuzz.txt"); });
  expect_only_input_errors(text, [](std::istream& in) { adit::eval::read_euroc_csv(in, "fuzz.csv"); });
  expect_only_input_errors(text, [](std::istream& in) { adit::eval::read_targets_csv(in, "fuzz.csv"); });
  expect_only_input_errors(text, [](std::istream& in) { adit::eval::read_people_truth(in, "fuzz.csv"); });
  expect_only_input_errors(text, [](std::istream& in) { adit::eval::read_loop_edges(in, "summary.json"); });
  return 0;
}
