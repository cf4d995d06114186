/* Side-by-side timing of robovec's binary64 C at batch=4 (A) against the mixed-precision C
 * `precision` chose at batch=8 (B) and the same formats with float arrays at batch=8 (C: the
 * caller's data already in binary32), for one function (scripts/precision_speed.sh writes the three files
 * with the symbols rv_a, rv_b, rv_c and -DNI/-DNO, the inputs and outputs per state).
 * Each rep times CALLS calls of each, alternating, the order rotated each rep; inputs cycle over
 * 64 states (uniform in [-1, 1]: the code has no data-dependent branch but for |x| > 2^11 in
 * trig=inline). Prints the median ns per state of each and the median of the paired ratios
 * A/B and A/C (both sides timed in the same rep). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

void rv_a(const double *restrict in, double *restrict out);
void rv_b(const double *restrict in, double *restrict out);
void rv_c(const float *restrict in, float *restrict out);

#define REPS 101
#define CALLS 1000
static double in_d[64][NI * 8], out_d[NO * 8];
static float in_f[64][NI * 8], out_f[NO * 8];

static double now_ns(void)
{
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec * 1e9 + t.tv_nsec;
}

static int cmp(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

static double median(double *x)
{
  qsort(x, REPS, sizeof *x, cmp);
  return x[REPS / 2];
}

static double time_one(int which)
{
  double t0 = now_ns();
  for (int k = 0; k < CALLS; k++) {
    if (which == 0) rv_a(in_d[k & 63], out_d);
    else if (which == 1) rv_b(in_d[k & 63], out_d);
    else rv_c(in_f[k & 63], out_f);
  }
  return (now_ns() - t0) / CALLS / (which == 0 ? 4 : 8);
}

int main(void)
{
  srand(1);
  for (int s = 0; s < 64; s++)
    for (int i = 0; i < NI * 8; i++) {
      in_d[s][i] = 2.0 * rand() / RAND_MAX - 1.0;
      in_f[s][i] = (float)in_d[s][i];
    }
  double ns[3][REPS], ab[REPS], ac[REPS];
  for (int r = 0; r < REPS; r++) {
    double t[3];
    for (int j = 0; j < 3; j++) {
      int w = (j + r) % 3;
      t[w] = time_one(w);
    }
    for (int w = 0; w < 3; w++) ns[w][r] = t[w];
    ab[r] = t[0] / t[1];
    ac[r] = t[0] / t[2];
  }
  double ma = median(ns[0]), mb = median(ns[1]), mc = median(ns[2]);
  printf("%.2f %.2f %.2f %.3f %.3f\n", ma, mb, mc, median(ab), median(ac));
  return 0;
}
