/* The binary32 sin/cos of codegen<c;trig=inline> against the C library's binary64 sin/cos, on
 * every binary32 argument of [-2^11, 2^11] (scripts/trig_ulps.sh; the allowance it checks is
 * robovec_passes::error_bound::bound::INLINE32_ULPS). Three kernels, as the back end writes
 * them: one state (sc1: robovec_sincos_inline), a float batch of 8 (sc8: the vector kernel), and
 * binary32 values in a double file (scm: robovec_sincos_inline32). The error is counted in the
 * allowance the bound gives one ulp, 2^-23·|y| + 2^-149 (|y| the exact value: rel = 2·2^-24 and
 * abs = 2·2^-150 per ulp, bound.rs): a figure below 1 is within it. The binary64 reference's own
 * error, below 2^-29 of the allowance, is left out. Exit 1 when an error reaches the allowance,
 * or a lane differs from the one-state kernel.
 * Usage: h [LO HI] (bit patterns, hex; default 0 .. 0x45000000 = 2^11; each with its negative). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
void sc1(const float *restrict in, float *restrict out);
void sc8(const float *restrict in, float *restrict out);
void scm(const double *restrict in, double *restrict out);

static double ulps(double c, double y) { return fabs(c - y) / (0x1p-23 * fabs(y) + 0x1p-149); }

int main(int argc, char **argv)
{
  uint32_t lo = 0, hi = 0x45000000u;
  if (argc > 2 && (sscanf(argv[1], "%x", &lo) != 1 || sscanf(argv[2], "%x", &hi) != 1)) return 2;
  double worst[3] = {0, 0, 0};
  float at[3] = {0, 0, 0};
  unsigned long long differ = 0, n = 0;
  for (uint64_t b0 = lo; b0 <= hi; b0 += 4) {
    float x[8], o1[2], o8[16];
    double xd[8], om[16];
    for (int l = 0; l < 8; l++) {
      uint64_t m = b0 + (uint64_t)(l >> 1);
      uint32_t b = (uint32_t)(m > hi ? hi : m) | ((uint32_t)(l & 1) << 31);
      memcpy(&x[l], &b, 4);
      xd[l] = x[l];
    }
    sc8(x, o8);
    scm(xd, om);
    for (int l = 0; l < 8; l++) {
      sc1(&x[l], o1);
      double s = sin((double)x[l]), c = cos((double)x[l]);
      double e[3] = {fmax(ulps(o1[0], s), ulps(o1[1], c)), fmax(ulps(o8[l], s), ulps(o8[8 + l], c)),
                     fmax(ulps(om[l], s), ulps(om[8 + l], c))};
      for (int k = 0; k < 3; k++)
        if (e[k] > worst[k]) { worst[k] = e[k]; at[k] = x[l]; }
      differ += o1[0] != o8[l] || o1[1] != o8[8 + l] || (float)om[l] != o1[0] || (float)om[8 + l] != o1[1];
      n++;
    }
  }
  float flo, fhi;
  memcpy(&flo, &lo, 4);
  memcpy(&fhi, &hi, 4);
  printf("%llu arguments, |x| in [%a, %a]: worst error / 1-ulp allowance: one state %.6f (x = %a), float batch %.6f (x = %a), "
         "binary32 in a double file %.6f (x = %a); lanes differing from one state: %llu\n",
         n, flo, fhi, worst[0], at[0], worst[1], at[1], worst[2], at[2], differ);
  return worst[0] >= 1.0 || worst[1] >= 1.0 || worst[2] >= 1.0 || differ != 0;
}
