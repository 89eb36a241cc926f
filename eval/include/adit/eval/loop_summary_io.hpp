#pragma once
// Reading what aditd's loop closer accepted from a session's summary.json
// ("loops": "edges", written by daemon/src/sessions.cpp): each loop in the
// graph, its measured relative pose and information (docs/LOOPS.md).
// Missing keys, wrong types and bad numbers throw adit::InputError naming the
// file and the key.

#include <filesystem>
#include <iosfwd>
#include <vector>

#include "adit/eval/loop_truth.hpp"

namespace adit::eval {

std::vector<LoopEdgeRecord> read_loop_edges(const std::filesystem::path& summary_json);
std::vector<LoopEdgeRecord> read_loop_edges(std::istream& in, const std::filesystem::path& name);

}  // namespace adit::eval
