#pragma once
// Splitting a text line into fields and parsing numbers without locales or
// exceptions: the shared core of the trajectory and target readers.

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace adit::eval::detail {

// Fields of `line` separated by any character of `separators`; runs of
// whitespace count as one separator, surrounding whitespace is dropped.
void split_fields(std::string_view line, std::string_view separators, std::vector<std::string_view>& out);

// A finite double (a leading '+' is accepted); nullopt otherwise.
std::optional<double> parse_double(std::string_view field);
std::optional<std::int64_t> parse_int64(std::string_view field);

// True for blank lines and '#' comments.
bool is_comment_or_blank(std::string_view line);

}  // namespace adit::eval::detail
