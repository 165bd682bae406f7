// Fills a buffer with a constant. The smallest program: the runtime's own tests build, cache,
// export and reload it without depending on any stage of the engine.
__kernel void fill_float(__global float* out, const float value, const int n) {
  const int i = (int)get_global_id(0);
  if (i < n) out[i] = value;
}
