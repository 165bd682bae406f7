// Where each sum sits in a row of the fused pass's partial sums (kernels/track/warp_reduce.cl
// writes them; track/warp_reduce.h's ReduceLayout reads them): one copy of the layout, in the
// subset of C that OpenCL C and C++ share. nj = parameters + 2 (the brightness gain and bias),
// bins = the histogram's bins. The sums from RR on exist only in the statistics variant.
#ifndef PLANARVO_KERNELS_TRACK_WARP_REDUCE_LAYOUT_H
#define PLANARVO_KERNELS_TRACK_WARP_REDUCE_LAYOUT_H

#define PV_REDUCE_NH(nj) ((nj) * ((nj) + 1) / 2)      // entries of an upper triangle
#define PV_REDUCE_JTJ 0                                // NH: upper triangle of J^T W J, row by row
#define PV_REDUCE_JTJ_AT(nj, i, j) ((i) * (nj) - (i) * ((i) - 1) / 2 + ((j) - (i)))  // its (i, j), i <= j
#define PV_REDUCE_JTR(nj) (PV_REDUCE_NH(nj))           // NJ: J^T W r
#define PV_REDUCE_COST(nj) (PV_REDUCE_NH(nj) + (nj))   // sum of Huber costs
#define PV_REDUCE_WRR(nj) (PV_REDUCE_COST(nj) + 1)     // sum of weight * r^2
#define PV_REDUCE_VALID(nj) (PV_REDUCE_COST(nj) + 2)   // pixels with a valid reference and live sample
#define PV_REDUCE_INLIER(nj) (PV_REDUCE_COST(nj) + 3)  // of those, |r| <= k
#define PV_REDUCE_REF(nj) (PV_REDUCE_COST(nj) + 4)     // pixels with a valid reference
#define PV_REDUCE_PLAIN_COUNT(nj) (PV_REDUCE_COST(nj) + 5)  // the row's length without statistics
// The statistics variant's:
#define PV_REDUCE_RR(nj) (PV_REDUCE_COST(nj) + 5)      // sum of r^2
#define PV_REDUCE_IREF(nj) (PV_REDUCE_COST(nj) + 6)    // sum of (I_r - 128) over valid pairs
#define PV_REDUCE_IREF2(nj) (PV_REDUCE_COST(nj) + 7)   // sum of (I_r - 128)^2 over valid pairs
#define PV_REDUCE_GLIVE(nj) (PV_REDUCE_COST(nj) + 8)   // sum of |grad I_l(w(p))|^2 over valid pairs
#define PV_REDUCE_GREF(nj) (PV_REDUCE_COST(nj) + 9)    // sum of |grad I_r(p)|^2 over valid pairs
#define PV_REDUCE_HVALID(nj) (PV_REDUCE_COST(nj) + 10) // valid pixels in the histogram's subsample
#define PV_REDUCE_HIST(nj) (PV_REDUCE_COST(nj) + 11)   // bins: counts of |r| < 0.25 * 2^(j / 2) in it
#define PV_REDUCE_JTJ_IN(nj, bins) (PV_REDUCE_HIST(nj) + (bins))  // NH: J^T J over the inliers
#define PV_REDUCE_STATS_COUNT(nj, bins) (PV_REDUCE_JTJ_IN(nj, bins) + PV_REDUCE_NH(nj))

#endif  // PLANARVO_KERNELS_TRACK_WARP_REDUCE_LAYOUT_H
