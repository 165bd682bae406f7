// Fills a buffer with a constant. The smallest program: the runtime's own tests build, cache,
// export and reload it without depending on any stage of the engine.
__kernel void fill_float(__global float* out, const float value, const int n) {
  const int i = (int)get_global_id(0);
  if (i < n) out[i] = value;
}

// The runtime's tests build with -D PLANARVO_TEST_BUILD_ERROR to check that a failed build's
// log reaches the user.
#ifdef PLANARVO_TEST_BUILD_ERROR
#error "planarvo test: requested build failure"
#endif
