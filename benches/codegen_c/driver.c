/* Timing driver of benches/codegen_c.rs: Robotran's own C and robovec's generated C for one
 * model, in one binary, alternating.
 *
 * `model.inc` (written by the harness) defines:
 *   NSETS, NNAMES, SETS[NSETS][NNAMES]: input states (every input name, trig values included);
 *   ROBOTRAN_KIND 0 (dirdyna: M, c) or 1 (invdyna: Qq), NOUT_ROBOTRAN, the dims of MbsData's arrays
 *   and fill_mbs(MbsData *s, const double *set): one state into a stub MbsData;
 *   NVARIANTS and VARIANTS[]: robovec's functions with their input maps (names -> SETS columns).
 * Output: one check line per variant (outputs compared, bit-identical, largest difference relative
 * to the largest |output|), then one time line per variant: name, median, min, max ns/state, then
 * the median, first and third quartiles of the paired ratio (Robotran's ns over the variant's ns
 * per state, both from the same rep); then, for each variant with a base variant (`base` >= 0:
 * the same code unsplit, `chunk=0`), one pair line: name, base name, median, first and third
 * quartiles of the paired ratio base's ns over the variant's (> 1: the variant is faster).
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mbs_data.h"

typedef void (*fn64)(const double *restrict, double *restrict);
typedef void (*fn32)(const float *restrict, float *restrict);

typedef struct {
    const char *name;
    fn64 f64;
    fn32 f32;
    int lanes;
    int nin, nout;
    const int *in_map;  /* SETS column of each input */
    const int *out_map; /* Robotran output index of each output (-1: none) */
    int base;           /* variant to pair against (-1: none) */
} Variant;

#include "model.inc"

/* After model.inc, which defines ROBOTRAN_KIND. */
#if ROBOTRAN_KIND == 0
void robotran_fn(double **M, double *c, MbsData *s, double tsim);
#else
void robotran_fn(double *Qq, MbsData *s, double tsim);
#endif

static double now_ns(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e9 + t.tv_nsec;
}

static double **matrix(int rows, int cols) {
    double **a = calloc(rows, sizeof *a);
    for (int i = 0; i < rows; i++) a[i] = calloc(cols, sizeof **a);
    return a;
}

static MbsData states[NSETS];
static double **M_out;
static double *c_out;
volatile double sink;

/* Robotran's result k (0-based, M row-major then c; or Qq). */
static double robotran_result(int k) {
#if ROBOTRAN_KIND == 0
    if (k < NDOF * NDOF) return M_out[1 + k / NDOF][1 + k % NDOF];
    return c_out[1 + k - NDOF * NDOF];
#else
    return c_out[1 + k];
#endif
}

static void run_robotran(int k) {
#if ROBOTRAN_KIND == 0
    robotran_fn(M_out, c_out, &states[k], 0.5);
    sink += c_out[1];
#else
    robotran_fn(c_out, &states[k], 0.5);
    sink += c_out[1];
#endif
}

static double *in64[NVARIANTS], *out64[NVARIANTS];
static float *in32[NVARIANTS], *out32[NVARIANTS];

/* Call k of a variant reads batch k % (NSETS / lanes): every variant cycles over the same
 * NSETS states (a batch of W lanes holds W of them), so every variant works on the same data
 * set — for coman's dirdyna 64 states are 374 KB, which stays in L2 — instead of a W times larger
 * one for a batch. */
static void run_variant(int v, int k) {
    const Variant *x = &VARIANTS[v];
    size_t stride = (size_t)x->nin * x->lanes;
    int nbatches = NSETS / x->lanes > 0 ? NSETS / x->lanes : 1;
    k %= nbatches;
    if (x->f64) {
        x->f64(in64[v] + (size_t)k * stride, out64[v]);
        sink += out64[v][0];
    } else {
        x->f32(in32[v] + (size_t)k * stride, out32[v]);
        sink += out32[v][0];
    }
}

static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv) {
    int reps = argc > 1 ? atoi(argv[1]) : 61;
    double target_ns = argc > 2 ? atof(argv[2]) : 5e5;
    for (int k = 0; k < NSETS; k++) fill_mbs(&states[k], SETS[k]);
    M_out = matrix(NDOF + 2, NDOF + 2);
    c_out = calloc(NOUT_ROBOTRAN + 2, sizeof *c_out);
    /* Batches: lane l of batch k is state (k*W + l) % NSETS. */
    for (int v = 0; v < NVARIANTS; v++) {
        const Variant *x = &VARIANTS[v];
        size_t n = (size_t)NSETS * x->nin * x->lanes;
        if (x->f64) {
            in64[v] = malloc(n * sizeof(double) + 64);
            out64[v] = calloc((size_t)x->nout * x->lanes + 1, sizeof(double));
        } else {
            in32[v] = malloc(n * sizeof(float) + 64);
            out32[v] = calloc((size_t)x->nout * x->lanes + 1, sizeof(float));
        }
        for (int k = 0; k < NSETS; k++)
            for (int i = 0; i < x->nin; i++)
                for (int l = 0; l < x->lanes; l++) {
                    double val = SETS[(k * x->lanes + l) % NSETS][x->in_map[i]];
                    size_t at = ((size_t)k * x->nin + i) * x->lanes + l;
                    if (x->f64) in64[v][at] = val; else in32[v][at] = (float)val;
                }
    }
    /* Check: each variant's lane 0 of batch 0 (state 0) against Robotran's C on state 0. */
    run_robotran(0);
    double *ref = malloc(sizeof(double) * (NOUT_ROBOTRAN + 1));
    for (int k = 0; k < NOUT_ROBOTRAN; k++) ref[k] = robotran_result(k);
    for (int v = 0; v < NVARIANTS; v++) {
        const Variant *x = &VARIANTS[v];
        run_variant(v, 0);
        double worst = 0, scale = 0;
        int same = 0, compared = 0;
        for (int k = 0; k < NOUT_ROBOTRAN; k++) scale = fmax(scale, fabs(ref[k]));
        for (int j = 0; j < x->nout; j++) {
            int r = x->out_map[j];
            if (r < 0) continue;
            double got = x->f64 ? out64[v][(size_t)j * x->lanes] : out32[v][(size_t)j * x->lanes];
            double d = fabs(got - ref[r]) / fmax(scale, 1e-300); /* normwise */
            if (got == ref[r]) same++;
            if (!(d <= worst)) worst = d; /* NaN propagates as worst */
            compared++;
        }
        printf("check\t%s\t%d\t%d\t%.3g\n", x->name, compared, same, worst);
    }
    /* Calibrate: calls per sample so that one sample takes about target_ns. */
    int nv = NVARIANTS + 1;
    long *calls = malloc(sizeof(long) * nv);
    for (int v = 0; v < nv; v++) {
        double t0 = now_ns();
        int n = 0;
        do {
            if (v == 0) run_robotran(n % NSETS); else run_variant(v - 1, n % NSETS);
            n++;
        } while (now_ns() - t0 < target_ns / 4);
        calls[v] = n * 4 > 0 ? n * 4 : 1;
    }
    double *samples = malloc(sizeof(double) * nv * reps);
    for (int r = 0; r < reps; r++) {
        for (int i = 0; i < nv; i++) {
            int v = (i + r) % nv; /* rotate who goes first */
            double t0 = now_ns();
            for (long n = 0; n < calls[v]; n++) {
                if (v == 0) run_robotran(n % NSETS); else run_variant(v - 1, n % NSETS);
            }
            double t = now_ns() - t0;
            int lanes = v == 0 ? 1 : VARIANTS[v - 1].lanes;
            samples[v * reps + r] = t / ((double)calls[v] * lanes);
        }
    }
    /* Paired ratios: Robotran's time over the variant's in the same rep (neighbouring samples),
     * which cancels the drifts of a shared machine that move both alike; median and quartiles. */
    double *ratio = malloc(sizeof(double) * nv * reps);
    for (int v = 0; v < nv; v++)
        for (int r = 0; r < reps; r++) ratio[v * reps + r] = samples[r] / samples[v * reps + r];
    /* Against the base variant, in the same rep (before the samples are sorted). */
    double *pair = malloc(sizeof(double) * nv * reps);
    for (int v = 1; v < nv; v++) {
        int b = VARIANTS[v - 1].base;
        if (b < 0) continue;
        for (int r = 0; r < reps; r++) pair[v * reps + r] = samples[(b + 1) * reps + r] / samples[v * reps + r];
    }
    for (int v = 0; v < nv; v++) {
        double *s = samples + v * reps, *q = ratio + v * reps;
        qsort(s, reps, sizeof *s, cmp);
        qsort(q, reps, sizeof *q, cmp);
        printf("time\t%s\t%.2f\t%.2f\t%.2f\t%.3f\t%.3f\t%.3f\n", v == 0 ? "robotran" : VARIANTS[v - 1].name,
               s[reps / 2], s[0], s[reps - 1], q[reps / 2], q[reps / 4], q[3 * reps / 4]);
    }
    for (int v = 1; v < nv; v++) {
        int b = VARIANTS[v - 1].base;
        if (b < 0) continue;
        double *q = pair + v * reps;
        qsort(q, reps, sizeof *q, cmp);
        printf("pair\t%s\t%s\t%.3f\t%.3f\t%.3f\n", VARIANTS[v - 1].name, VARIANTS[b].name, q[reps / 2], q[reps / 4],
               q[3 * reps / 4]);
    }
    return sink == 12345.678 ? 1 : 0;
}
