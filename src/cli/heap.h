// The tool's heap, set up for a short run (heap.cpp).
#pragma once

namespace planarvo::cli {

// Keeps glibc malloc's allocations in one brk heap that grows in large steps and asks the kernel
// for transparent huge pages there (where THP is "madvise" or "always"). Called once by a
// command that is short and bound by its allocations (`posegraph`), not by the ones that run the
// engine for minutes. Does nothing under the sanitizers (their allocators own the heap) or where
// the kernel refuses.
void prepare_heap();

}  // namespace planarvo::cli
