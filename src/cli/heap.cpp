// Why: a `planarvo posegraph` process lives for milliseconds to seconds and touches each page of
// its heap once. On a virtual machine (this project's build and CI machines among them) the first
// touch of a 4 KiB page costs about 11 µs (the fault, zeroing, the hypervisor's mapping), and of
// a 2 MiB transparent huge page about 0.35 µs per 4 KiB (test/bench/results/graph.md, "Whole-process
// time"). `planarvo posegraph intel.g2o` took 1,100 page faults, a third of its run.
//
// What: glibc's malloc (mallopt) keeps blocks up to 64 MiB in the brk heap instead of a fresh
// mmap each, grows the heap in 32 MiB steps and never trims it; the heap's 2 MiB-aligned span is
// then marked MADV_HUGEPAGE. Memory is committed only as it is touched, so a step costs address
// space, not RAM. glibc's own switch (GLIBC_TUNABLES=glibc.malloc.hugetlb=1) can only be set
// before the process starts.
#include "heap.h"

#include <cstdint>
#include <cstdlib>

#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define PLANARVO_SANITIZED_HEAP 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define PLANARVO_SANITIZED_HEAP 1
#endif
#endif

namespace planarvo::cli {
#if !defined(PLANARVO_SANITIZED_HEAP) && defined(__GLIBC__) && defined(MADV_HUGEPAGE)
namespace {
void* volatile heap_filler = nullptr;  // kept, so that the compiler cannot drop the allocation
}  // namespace
#endif

void prepare_heap() {
#if !defined(PLANARVO_SANITIZED_HEAP) && defined(__GLIBC__) && defined(MADV_HUGEPAGE)
  constexpr std::size_t kStep = std::size_t{32} << 20;
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  mallopt(M_MMAP_THRESHOLD, 64 << 20);  // fixed: also stops glibc's dynamic threshold
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  mallopt(M_TOP_PAD, static_cast<int>(kStep));
  // Grow the heap now by one step (the probe is larger than the initial heap); the probe block is
  // then the start of the heap's top chunk. Freeing it wrote a header just past its end: the
  // huge-page span starts beyond that, since a 2 MiB range with one 4 KiB page already mapped
  // can no longer get a huge page.
  constexpr std::size_t kProbe = std::size_t{256} << 10;
  void* probe = std::malloc(kProbe);
  if (!probe) return;
  const auto top = reinterpret_cast<std::uintptr_t>(probe);
  std::free(probe);
  const auto end = reinterpret_cast<std::uintptr_t>(sbrk(0));
  const std::uintptr_t a = (top + kProbe + 64 + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t b = end & ~(kHuge - 1);
  if (end == static_cast<std::uintptr_t>(-1) || end < top || end - top > 2 * kStep ||
      b < a + kHuge)
    return;  // not one contiguous brk heap: leave it as it is
  // Fill the top up to the first 2 MiB boundary, so that what the command allocates next lies in
  // huge-page-backed memory. The filler is never touched (address space, no RAM) and never freed.
  if (a - top > 64) {
    heap_filler = std::malloc(a - top - 32);  // 32: this block's and the next one's headers
  }
  madvise(reinterpret_cast<void*>(a), b - a, MADV_HUGEPAGE);  // a refusal changes nothing
#endif
}

}  // namespace planarvo::cli
