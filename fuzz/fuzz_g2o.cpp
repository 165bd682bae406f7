// A g2o pose graph through planarvo_posegraph_optimize (what `planarvo posegraph` calls): read,
// a few solver iterations, the result written. Both initialisations are exercised.
#include <cstring>

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace planarvo_fuzz;
  static const std::string in = work_dir() + "/graph.g2o";
  static const std::string out = work_dir() + "/graph_out.g2o";
  write_file(in, data, size);
  planarvo_posegraph_options options;
  planarvo_posegraph_options_init(&options);
  options.max_iterations = 3;
  options.init = size % 2 ? PLANARVO_POSEGRAPH_INIT_ROTATION_FIRST : PLANARVO_POSEGRAPH_INIT_NONE;
  planarvo_solver_summary summary;
  std::memset(&summary, 0, sizeof summary);
  summary.struct_size = sizeof summary;
  const planarvo_status st = planarvo_posegraph_optimize(in.c_str(), out.c_str(), &options, &summary);
  check_status(st);
  if (st != PLANARVO_OK && st != PLANARVO_ERROR_FAILED && st != PLANARVO_ERROR_INVALID_INPUT)
    broken("a bad g2o file gave a status other than INVALID_INPUT or FAILED");
  if (st == PLANARVO_OK && !(is_finite(summary.final_chi2) && is_finite(summary.initial_chi2)))
    broken("a solved graph with a non-finite chi2");
  return 0;
}
