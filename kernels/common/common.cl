// Helpers shared by the image pipeline's programs. The runtime prepends this file to every
// program (src/ocl/README.md), so names carry the pv_ / PV_ prefix to stay out of the way.

// pipeline.h's kInvalidIntensity: the value of a pixel that is not valid in the intensity images
// between stages. So negative that any weighted sum with an invalid term of weight >= 1 is
// negative, so validity can be read from a sum's sign.
#define PV_INVALID (-1048576.0f)

// Stores the first n (1..7) elements of v at d: the tail of a row processed 8 pixels at a time.
inline void pv_store_head(const float8 v, __global float* d, const int n) {
  d[0] = v.s0;
  if (n > 1) d[1] = v.s1;
  if (n > 2) d[2] = v.s2;
  if (n > 3) d[3] = v.s3;
  if (n > 4) d[4] = v.s4;
  if (n > 5) d[5] = v.s5;
  if (n > 6) d[6] = v.s6;
}

// The first n (1..7) elements at s, the rest `fill`: the tail of a row read 8 pixels at a time.
inline float8 pv_load_head(__global const float* s, const int n, const float fill) {
  float8 v = (float8)(fill);
  v.s0 = s[0];
  if (n > 1) v.s1 = s[1];
  if (n > 2) v.s2 = s[2];
  if (n > 3) v.s3 = s[3];
  if (n > 4) v.s4 = s[4];
  if (n > 5) v.s5 = s[5];
  if (n > 6) v.s6 = s[6];
  return v;
}
