#pragma once
// The memory of this process, as the benches and `adit replay` report it.

namespace adit::tools {

// Resident set size now, MiB (/proc/self/statm, proc(5)).
double resident_mb();
// Peak resident set size so far, MiB (getrusage ru_maxrss).
double peak_resident_mb();
// Bytes malloc has handed out and not taken back, in every arena and mmapped
// block, MiB (glibc mallinfo2; -1 elsewhere). Against the resident size it
// tells live data from what the allocator holds free (fragmentation). It
// locks each arena while it walks its free lists: sample it sparingly.
double heap_in_use_mb();

}  // namespace adit::tools
