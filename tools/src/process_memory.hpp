#pragma once
// The memory of this process, as the benches and `adit replay` report it.

namespace adit::tools {

// Resident set size now, MiB (/proc/self/statm, proc(5)).
double resident_mb();
// Peak resident set size so far, MiB (getrusage ru_maxrss).
double peak_resident_mb();

}  // namespace adit::tools
