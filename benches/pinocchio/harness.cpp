// Timing and value harness of `cargo bench --bench pinocchio` (issues 14, 30, 50): Pinocchio's C++
// `rnea`, `crba`, `crba` + `nonLinearEffects`, `aba`, `computeRNEADerivatives`,
// `computeABADerivatives` and `computeMinverse` against Pinocchio's CppADCodeGen C (`cg_export.cpp`:
// all but `crba` + `nonLinearEffects`) and robovec's generated C, on the same states.
//
//   harness MODEL.txt STATES.txt VALUES.bin REPS
//
// MODEL.txt is `model.saveToText` of `export_model.py`, STATES.txt its states (format in that
// script). robovec's side is linked in from `table.c` (written by the bench): `RV_SETS` holds every
// robovec input of every state (`RV_NCOLS` columns), `RV_VARIANTS` the generated functions with
// their group (0: inverse dynamics vs `rnea`; 1: `M` vs `crba`; 2: `M`, `c` vs `crba` +
// `nonLinearEffects`; 3: forward dynamics vs `aba`; 4: `dtau_dq`, `dtau_dv` vs
// `computeRNEADerivatives`; 5: `ddq_dq`, `ddq_dv`, `Minv` vs `computeABADerivatives`; 6: `M^-1` vs
// `computeMinverse`), lanes per call, and maps: input k reads column `in_map[k]` (a negative
// `-1 - i`: the generalised force `tau[i]` of the state, the ABA's input, computed here), output
// k is entry `out_map[k]` of the group's layout (0: `tau[i]`; 1: `M[i][j]` at `i*nv + j`; 2: that,
// then `c[i]` at `nv*nv + i`; 3: `qdd[i]`; 4: `dtau_dq`, then `dtau_dv`, each nv x nv row-major;
// 5: `ddq_dq`, `ddq_dv`, `Minv` likewise; 6: `Minv[i][j]` at `i*nv + j`). In groups 1, 2 and 6
// every side computes the upper triangle (`crba`'s and `computeMinverse`'s) and the lower one is
// mirrored from it. `RV_GROUPS` (a bit per group) says which groups run: the others have no
// contestant and no values. `CG_VARIANTS` (also in `table.c`) are CppADCodeGen's functions, each
// compiled on its own (`cg_F_forward_zero` renamed per build), one state per call: groups 0 and 4
// read (q, v, a), 1 and 6 q, 3 and 5 (q, v, tau) in Pinocchio's layout; the outputs of groups 1
// and 6 are the upper triangle row by row (`M(i, j)`, `j >= i`), those of 4 and 5 the group's
// layout.
//
// The ABA's input `tau` of a state is the reference inverse dynamics of that state (below) rounded
// to double, the same for every contestant; its reference is the `long double` ABA from it, so
// `qdd` is close to the state's accelerations.
//
// The derivatives with respect to `q` are Pinocchio's: along the tangent space on a free flyer.
//
// Prints `contestant\tINDEX\tGROUP\tNAME` per contestant, then `time\tINDEX\tREP\tNS_PER_STATE` for
// every rep: in each rep every contestant of a group is timed once, the group's order rotated by
// one each rep, a sample being enough calls for ~0.3 ms, cycling over all states (a batch of W
// lanes takes W consecutive states). Writes VALUES.bin, native f64: per group, the reference
// (Pinocchio on `long double`, its 64-bit significand, rounded to f64 once), then each
// contestant's values in index order, each block `nsets x group size`.
#include "pinocchio/algorithm/aba-derivatives.hpp"
#include "pinocchio/algorithm/aba.hpp"
#include "pinocchio/algorithm/crba.hpp"
#include "pinocchio/algorithm/joint-configuration.hpp"
#include "pinocchio/algorithm/rnea-derivatives.hpp"
#include "pinocchio/algorithm/rnea.hpp"
#include "pinocchio/multibody.hpp"
#include "pinocchio/serialization.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

extern "C" {
typedef void (*rv_fn)(const double *in, double *out);
typedef struct {
  const char *label;
  rv_fn fn;
  int group;
  int batch;
  int n_in;
  int n_out;
  const int *in_map;
  const int *out_map;
} RvVariant;
extern const int RV_NSETS, RV_NCOLS, RV_NVARIANTS, RV_GROUPS;
extern const double RV_SETS[];
extern const RvVariant RV_VARIANTS[];

// CppADCodeGen's function (its `cg_F_forward_zero.c`); no atomic functions are used.
typedef struct Array {
  void *data;
  unsigned long size;
  int sparse;
  const unsigned long *idx;
  unsigned long nnz;
} Array;
struct LangCAtomicFun {
  void *libModel;
  int (*forward)(void *libModel, int atomicIndex, int q, int p, const Array tx[], Array *ty);
  int (*reverse)(void *libModel, int atomicIndex, int p, const Array tx[], Array *px, const Array py[]);
};
typedef void (*cg_fn)(double const *const *in, double *const *out, struct LangCAtomicFun atomic);
typedef struct {
  const char *label;
  cg_fn fn;
  int group;
} CgVariant;
extern const int CG_NVARIANTS;
extern const CgVariant CG_VARIANTS[];
}

typedef Eigen::Matrix<long double, Eigen::Dynamic, 1> VecL;
typedef Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic> MatL;

struct Contestant {
  std::string name;
  int group;
  int batch;
  // Evaluates block `k` (states k*batch .. k*batch + batch - 1).
  std::function<void(int)> call;
  // Values of state `s` in the group's layout.
  std::function<void(int, double *)> values;
};

static double now_ns() {
  return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

int main(int argc, char **argv) {
  if (argc != 5 && argc != 6) {
    std::fprintf(stderr, "usage: harness MODEL.txt STATES.txt VALUES.bin REPS [SAMPLE_NS]\n");
    return 2;
  }
  pinocchio::Model model;
  model.loadFromText(argv[1]);
  pinocchio::Data data(model);
  std::ifstream in(argv[2]);
  int n = 0, nq = 0, nv = 0;
  in >> n >> nq >> nv;
  if (!in || n != RV_NSETS || nq != model.nq || nv != model.nv) {
    std::fprintf(stderr, "%s: %d states nq %d nv %d; expected %d states nq %d nv %d\n", argv[2], n, nq, nv, RV_NSETS,
                 model.nq, model.nv);
    return 1;
  }
  double g[3];
  in >> g[0] >> g[1] >> g[2];
  std::vector<int> idx_q(nv), kind(nv);
  for (int i = 0; i < nv; i++) in >> idx_q[i] >> kind[i];
  std::vector<Eigen::VectorXd> x(n, Eigen::VectorXd(nv)), q(n, Eigen::VectorXd(nq)), v(n, Eigen::VectorXd(nv)),
      a(n, Eigen::VectorXd(nv));
  for (int s = 0; s < n; s++) {
    for (int i = 0; i < nv; i++) in >> x[s][i];
    for (int i = 0; i < nq; i++) in >> q[s][i];
    for (int i = 0; i < nv; i++) in >> v[s][i];
    for (int i = 0; i < nv; i++) in >> a[s][i];
  }
  if (!in) {
    std::fprintf(stderr, "%s: truncated\n", argv[2]);
    return 1;
  }
  const int reps = std::atoi(argv[4]);
  // Sample length, ns (argv[5], default 0.3 ms): long samples amortise the first calls after
  // the other contestants ran, which fetch a large function's code from the L3 or memory.
  const double sample_ns = argc > 5 ? std::atof(argv[5]) : 3e5;
  const int ngroups = 7;
  const int sizes[ngroups] = {nv, nv * nv, nv * nv + nv, nv, 2 * nv * nv, 3 * nv * nv, nv * nv};
  auto runs = [](int gi) { return (RV_GROUPS >> gi) & 1; };
  // Groups whose matrix is the upper triangle, mirrored into the lower one.
  auto upper = [](int gi) { return gi == 1 || gi == 2 || gi == 6; };

  // The reference: Pinocchio on long double, each configuration rebuilt from the exact
  // coordinates (a continuous joint's cos, sin in long double, not Pinocchio's rounded doubles;
  // a free-flyer's position and quaternion are the inputs' doubles, as every contestant's).
  pinocchio::ModelTpl<long double> model_l = model.cast<long double>();
  pinocchio::DataTpl<long double> data_l(model_l);
  std::vector<std::vector<double>> ref(ngroups, std::vector<double>());
  for (int gi = 0; gi < ngroups; gi++) ref[gi].resize((size_t)n * sizes[gi]);
  MatL dl1(nv, nv), dl2(nv, nv), dl3(nv, nv);
  // The ABA's input: the reference `tau` rounded to double.
  std::vector<Eigen::VectorXd> tau_d(n, Eigen::VectorXd(nv));
  for (int s = 0; s < n; s++) {
    VecL ql = q[s].cast<long double>();
    for (int i = 0; i < nv; i++) {
      long double xi = x[s][i];
      if (kind[i] == 2) continue;  // the free-flyer's configuration is q[0..7] itself
      if (kind[i] == 1) {
        ql[idx_q[i]] = std::cos(xi);
        ql[idx_q[i] + 1] = std::sin(xi);
      } else {
        ql[idx_q[i]] = xi;
      }
    }
    VecL vl = v[s].cast<long double>(), al = a[s].cast<long double>();
    VecL tau = pinocchio::rnea(model_l, data_l, ql, vl, al);
    MatL m = pinocchio::crba(model_l, data_l, ql);
    VecL nle = pinocchio::nonLinearEffects(model_l, data_l, ql, vl);
    for (int i = 0; i < nv; i++) tau_d[s][i] = (double)tau[i];
    VecL ddq = pinocchio::aba(model_l, data_l, ql, vl, VecL(tau_d[s].cast<long double>()));
    for (int i = 0; i < nv; i++) {
      ref[0][(size_t)s * sizes[0] + i] = (double)tau[i];
      ref[3][(size_t)s * sizes[3] + i] = (double)ddq[i];
      ref[2][(size_t)s * sizes[2] + nv * nv + i] = (double)nle[i];
      for (int j = 0; j < nv; j++) {
        double mij = (double)(i <= j ? m(i, j) : m(j, i));
        ref[1][(size_t)s * sizes[1] + i * nv + j] = mij;
        ref[2][(size_t)s * sizes[2] + i * nv + j] = mij;
      }
    }
    if (runs(4)) {
      dl1.setZero(), dl2.setZero(), dl3.setZero();
      pinocchio::computeRNEADerivatives(model_l, data_l, ql, vl, al, dl1, dl2, dl3);
      for (int k = 0; k < nv * nv; k++) {
        ref[4][(size_t)s * sizes[4] + k] = (double)dl1(k / nv, k % nv);
        ref[4][(size_t)s * sizes[4] + nv * nv + k] = (double)dl2(k / nv, k % nv);
      }
    }
    if (runs(5)) {
      dl1.setZero(), dl2.setZero(), dl3.setZero();
      pinocchio::computeABADerivatives(model_l, data_l, ql, vl, VecL(tau_d[s].cast<long double>()), dl1, dl2, dl3);
      for (int k = 0; k < nv * nv; k++) {
        ref[5][(size_t)s * sizes[5] + k] = (double)dl1(k / nv, k % nv);
        ref[5][(size_t)s * sizes[5] + nv * nv + k] = (double)dl2(k / nv, k % nv);
        ref[5][(size_t)s * sizes[5] + 2 * nv * nv + k] = (double)dl3(k / nv, k % nv);
      }
    }
    if (runs(6)) {
      pinocchio::computeMinverse(model_l, data_l, ql);
      for (int i = 0; i < nv; i++)
        for (int j = 0; j < nv; j++)
          ref[6][(size_t)s * sizes[6] + i * nv + j] = (double)(i <= j ? data_l.Minv(i, j) : data_l.Minv(j, i));
    }
  }

  // Contestants: Pinocchio's algorithms, then CppADCodeGen's functions, then robovec's variants.
  std::vector<Contestant> cs;
  volatile double sink = 0;
  auto mirror = [nv](const Eigen::MatrixXd &m, double *out) {
    for (int i = 0; i < nv; i++)
      for (int j = 0; j < nv; j++) out[i * nv + j] = i <= j ? m(i, j) : m(j, i);
  };
  cs.push_back({"pinocchio rnea", 0, 1, [&](int k) { pinocchio::rnea(model, data, q[k], v[k], a[k]); },
                [&](int s, double *out) {
                  Eigen::VectorXd t = pinocchio::rnea(model, data, q[s], v[s], a[s]);
                  for (int i = 0; i < nv; i++) out[i] = t[i];
                }});
  for (int world = 0; world < 2; world++) {
    pinocchio::Convention conv = world ? pinocchio::Convention::WORLD : pinocchio::Convention::LOCAL;
    std::string cname = world ? "WORLD" : "LOCAL";
    cs.push_back({"pinocchio crba " + cname, 1, 1, [&, conv](int k) { pinocchio::crba(model, data, q[k], conv); },
                  [&, conv](int s, double *out) { mirror(pinocchio::crba(model, data, q[s], conv), out); }});
    cs.push_back({"pinocchio crba " + cname + " + nonLinearEffects", 2, 1,
                  [&, conv](int k) {
                    pinocchio::crba(model, data, q[k], conv);
                    pinocchio::nonLinearEffects(model, data, q[k], v[k]);
                  },
                  [&, conv](int s, double *out) {
                    mirror(pinocchio::crba(model, data, q[s], conv), out);
                    Eigen::VectorXd c = pinocchio::nonLinearEffects(model, data, q[s], v[s]);
                    for (int i = 0; i < nv; i++) out[nv * nv + i] = c[i];
                  }});
  }
  for (int world = 0; world < 2; world++) {
    pinocchio::Convention conv = world ? pinocchio::Convention::WORLD : pinocchio::Convention::LOCAL;
    cs.push_back({std::string("pinocchio aba ") + (world ? "WORLD" : "LOCAL"), 3, 1,
                  [&, conv](int k) { pinocchio::aba(model, data, q[k], v[k], tau_d[k], conv); },
                  [&, conv](int s, double *out) {
                    Eigen::VectorXd d = pinocchio::aba(model, data, q[s], v[s], tau_d[s], conv);
                    for (int i = 0; i < nv; i++) out[i] = d[i];
                  }});
  }
  Eigen::MatrixXd d1 = Eigen::MatrixXd::Zero(nv, nv), d2 = d1, d3 = d1;
  cs.push_back({"pinocchio computeRNEADerivatives", 4, 1,
                [&](int k) { pinocchio::computeRNEADerivatives(model, data, q[k], v[k], a[k], d1, d2, d3); },
                [&](int s, double *out) {
                  pinocchio::computeRNEADerivatives(model, data, q[s], v[s], a[s], d1, d2, d3);
                  for (int k = 0; k < nv * nv; k++) out[k] = d1(k / nv, k % nv), out[nv * nv + k] = d2(k / nv, k % nv);
                }});
  cs.push_back({"pinocchio computeABADerivatives", 5, 1,
                [&](int k) { pinocchio::computeABADerivatives(model, data, q[k], v[k], tau_d[k], d1, d2, d3); },
                [&](int s, double *out) {
                  pinocchio::computeABADerivatives(model, data, q[s], v[s], tau_d[s], d1, d2, d3);
                  for (int k = 0; k < nv * nv; k++)
                    out[k] = d1(k / nv, k % nv), out[nv * nv + k] = d2(k / nv, k % nv),
                    out[2 * nv * nv + k] = d3(k / nv, k % nv);
                }});
  cs.push_back({"pinocchio computeMinverse", 6, 1, [&](int k) { pinocchio::computeMinverse(model, data, q[k]); },
                [&](int s, double *out) {
                  pinocchio::computeMinverse(model, data, q[s]);
                  for (int i = 0; i < nv; i++)
                    for (int j = 0; j < nv; j++) out[i * nv + j] = i <= j ? data.Minv(i, j) : data.Minv(j, i);
                }});
  // Only the groups that run keep their contestants.
  {
    std::vector<Contestant> kept;
    for (auto &c : cs)
      if (runs(c.group)) kept.push_back(c);
    cs.swap(kept);
  }
  // CppADCodeGen: each state's input vector packed once per group, one call per state.
  const struct LangCAtomicFun no_atomic = {nullptr, nullptr, nullptr};
  std::vector<std::vector<double>> cg_in(ngroups);
  std::vector<int> cg_n_in(ngroups, 0), cg_n_out(ngroups, 0);
  cg_n_in[0] = cg_n_in[3] = cg_n_in[4] = cg_n_in[5] = nq + 2 * nv;
  cg_n_in[1] = cg_n_in[6] = nq;
  cg_n_out[0] = cg_n_out[3] = nv;
  cg_n_out[1] = cg_n_out[6] = nv * (nv + 1) / 2;
  cg_n_out[4] = 2 * nv * nv;
  cg_n_out[5] = 3 * nv * nv;
  for (int gi : {0, 1, 3, 4, 5, 6}) {
    cg_in[gi].resize((size_t)n * cg_n_in[gi]);
    for (int s = 0; s < n; s++) {
      double *x = cg_in[gi].data() + (size_t)s * cg_n_in[gi];
      for (int i = 0; i < nq; i++) x[i] = q[s][i];
      if (gi == 1 || gi == 6) continue;
      for (int i = 0; i < nv; i++) {
        x[nq + i] = v[s][i];
        x[nq + nv + i] = gi == 0 || gi == 4 ? a[s][i] : tau_d[s][i];
      }
    }
  }
  std::vector<std::vector<double>> cg_out(CG_NVARIANTS);
  for (int ci = 0; ci < CG_NVARIANTS; ci++) {
    const int gi = CG_VARIANTS[ci].group;
    if (gi < 0 || gi >= ngroups || gi == 2 || !runs(gi)) {
      std::fprintf(stderr, "CppADCodeGen variant %s: group %d\n", CG_VARIANTS[ci].label, gi);
      return 1;
    }
    cg_out[ci].resize(cg_n_out[gi]);
    cs.push_back({std::string("cg ") + CG_VARIANTS[ci].label, gi, 1,
                  [&, ci, gi](int k) {
                    const double *ins[1] = {cg_in[gi].data() + (size_t)k * cg_n_in[gi]};
                    double *outs[1] = {cg_out[ci].data()};
                    CG_VARIANTS[ci].fn(ins, outs, no_atomic);
                  },
                  [&, ci, gi, nv](int s, double *out) {
                    const double *ins[1] = {cg_in[gi].data() + (size_t)s * cg_n_in[gi]};
                    std::vector<double> o(cg_n_out[gi]);
                    double *outs[1] = {o.data()};
                    CG_VARIANTS[ci].fn(ins, outs, no_atomic);
                    if (!upper(gi)) {
                      for (int i = 0; i < cg_n_out[gi]; i++) out[i] = o[i];
                      return;
                    }
                    int k = 0;
                    for (int i = 0; i < nv; i++)
                      for (int j = i; j < nv; j++) out[i * nv + j] = out[j * nv + i] = o[k++];
                  }});
  }
  // robovec: inputs packed once per variant, lane-contiguous (`in[i*W + lane]`).
  std::vector<std::vector<double>> packed(RV_NVARIANTS), outbuf(RV_NVARIANTS);
  for (int vi = 0; vi < RV_NVARIANTS; vi++) {
    const RvVariant &rv = RV_VARIANTS[vi];
    const int w = rv.batch;
    if (n % w != 0) {
      std::fprintf(stderr, "%d states are not a whole number of %d-lane batches\n", n, w);
      return 1;
    }
    packed[vi].resize((size_t)n * rv.n_in);
    outbuf[vi].resize((size_t)rv.n_out * w);
    for (int b = 0; b < n / w; b++)
      for (int lane = 0; lane < w; lane++)
        for (int i = 0; i < rv.n_in; i++) {
          const int s = b * w + lane, m = rv.in_map[i];
          packed[vi][((size_t)b * rv.n_in + i) * w + lane] =
              m >= 0 ? RV_SETS[(size_t)s * RV_NCOLS + m] : tau_d[s][-1 - m];
        }
    cs.push_back({std::string("robovec ") + rv.label, rv.group, w,
                  [&, vi](int k) {
                    const RvVariant &r = RV_VARIANTS[vi];
                    r.fn(packed[vi].data() + (size_t)k * r.n_in * r.batch, outbuf[vi].data());
                  },
                  [&, vi, nv, upper](int s, double *out) {
                    const RvVariant &r = RV_VARIANTS[vi];
                    const int b = s / r.batch, lane = s % r.batch;
                    std::vector<double> o((size_t)r.n_out * r.batch);
                    r.fn(packed[vi].data() + (size_t)b * r.n_in * r.batch, o.data());
                    for (int k = 0; k < r.n_out; k++)
                      if (r.out_map[k] >= 0) out[r.out_map[k]] = o[(size_t)k * r.batch + lane];
                    // robovec's M and M^-1 are the upper triangle, as crba's and
                    // computeMinverse's: mirrored like theirs.
                    if (upper(r.group))
                      for (int i = 0; i < nv; i++)
                        for (int j = 0; j < i; j++) out[i * nv + j] = out[j * nv + i];
                  }});
  }

  // Values.
  {
    std::ofstream f(argv[3], std::ios::binary);
    for (int gi = 0; gi < ngroups; gi++) {
      if (!runs(gi)) continue;
      f.write((const char *)ref[gi].data(), ref[gi].size() * sizeof(double));
      for (size_t c = 0; c < cs.size(); c++) {
        if (cs[c].group != gi) continue;
        std::vector<double> vals((size_t)n * sizes[gi], std::numeric_limits<double>::quiet_NaN());
        for (int s = 0; s < n; s++) cs[c].values(s, vals.data() + (size_t)s * sizes[gi]);
        f.write((const char *)vals.data(), vals.size() * sizeof(double));
      }
    }
    if (!f) {
      std::fprintf(stderr, "cannot write %s\n", argv[3]);
      return 1;
    }
  }
  for (size_t c = 0; c < cs.size(); c++) std::printf("contestant\t%zu\t%d\t%s\n", c, cs[c].group, cs[c].name.c_str());

  // Calibration: calls per sample for ~sample_ns.
  std::vector<long> calls(cs.size());
  for (size_t c = 0; c < cs.size(); c++) {
    const int blocks = n / cs[c].batch;
    long k = 0;
    double t0 = now_ns();
    while (now_ns() - t0 < 2e6) cs[c].call((int)(k++ % blocks));
    double per = (now_ns() - t0) / (double)k;
    calls[c] = std::max(1L, (long)(sample_ns / per));
  }
  for (int rep = 0; rep < reps; rep++) {
    for (int gi = 0; gi < ngroups; gi++) {
      if (!runs(gi)) continue;
      std::vector<size_t> members;
      for (size_t c = 0; c < cs.size(); c++)
        if (cs[c].group == gi) members.push_back(c);
      for (size_t m = 0; m < members.size(); m++) {
        const size_t c = members[(m + rep) % members.size()];
        const int blocks = n / cs[c].batch;
        double t0 = now_ns();
        for (long k = 0; k < calls[c]; k++) cs[c].call((int)(k % blocks));
        double t = now_ns() - t0;
        std::printf("time\t%zu\t%d\t%.4f\n", c, rep, t / (double)(calls[c] * cs[c].batch));
      }
    }
  }
  sink = sink + data.tau[0];
  return 0;
}
