// Pinocchio's own code generator, CppADCodeGen (`pinocchio/codegen/cppadcg-algo.hpp`), writing its
// C sources for one model: the peer robovec's generated dynamics (issue 30) and derivatives
// (issue 50) are compared with. Built and run by `cg_sources.py`.
//
//   cg_export MODEL.txt OUTDIR FUNCTION...
//
// MODEL.txt is `model.saveToText` of `export_model.py`. For each FUNCTION writes OUTDIR/FUNCTION,
// CppADCodeGen's library sources; the function itself is `cg_FUNCTION_forward_zero.c` (`void
// cg_FUNCTION_forward_zero(double const *const *in, double *const *out, struct LangCAtomicFun)`),
// in[0] and out[0] in Pinocchio's layout:
//
//   rnea              `CodeGenRNEA`: (q, v, a) -> tau
//   crba              `CodeGenCRBA`: q -> M, the upper triangle row by row (`M(i, j)`, j >= i)
//   aba               `CodeGenABA`: (q, v, tau) -> ddq
//   minv              `CodeGenMinv`: q -> M^-1, the upper triangle row by row
//   rnea_derivatives  `CodeGenRNEADerivatives`' tape, outputs cut to robovec's (below):
//                     (q, v, a) -> dtau_dq, dtau_dv (nv x nv each, row-major)
//   aba_derivatives   `CodeGenABADerivatives`: (q, v, tau) -> ddq_dq, ddq_dv, ddq_dtau = M^-1
//                     (nv x nv each, row-major; M^-1 both triangles)
//
// Only the zero-order forward function is generated (no Jacobian), as Pinocchio's `timings-cg`
// times it. `CodeGenRNEADerivatives` also outputs `dtau_da` (the upper triangle of `M`, which
// `computeRNEADerivatives` fills as a by-product); robovec's `rnea_derivatives` has no such
// output (`crba` is its function for `M`), so `RneaDerivatives` records the same tape
// (`computeRNEADerivatives` on CppAD scalars, `optimize("no_compare_op")` as Pinocchio's class)
// with `dtau_dq` and `dtau_dv` only: CppAD's optimiser drops what only `M` needed, and both
// sides compute the same entries.
//
// `ModelLibraryCSourceGen::saveSources` of CppADCodeGen 2.4.3 does not compile (it calls a
// protected `getSources()` without arguments); `SaveFilesModelLibraryProcessor` writes the same
// files. `CodeGenBase` keeps its source generator protected, hence the subclass.
#include "pinocchio/codegen/cppadcg-algo.hpp"
#include "pinocchio/serialization.hpp"

#include <cstdio>
#include <string>

template<class G>
struct Export : G {
  using G::G;
  void save(const std::string &dir) {
    this->build_jacobian = false;
    this->initLib();
    CppAD::cg::SaveFilesModelLibraryProcessor<double>::saveLibrarySourcesTo(*this->libcgen_ptr, dir);
  }
};

// `CodeGenRNEADerivatives` without its `dtau_da` output (see above).
struct RneaDerivatives : pinocchio::CodeGenBase<double> {
  typedef pinocchio::CodeGenBase<double> Base;
  typedef Eigen::Matrix<ADScalar, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> RowAD;

  RneaDerivatives(const Model &model, const std::string &function_name, const std::string &library_name)
      : Base(model, model.nq + 2 * model.nv, 2 * model.nv * model.nv, function_name, library_name) {}

  void buildMap() override {
    CppAD::Independent(ad_X);
    const Eigen::Index nq = ad_model.nq, nv = ad_model.nv;
    ADConfigVectorType q = ad_X.segment(0, nq);
    ADTangentVectorType v = ad_X.segment(nq, nv), a = ad_X.segment(nq + nv, nv);
    ADMatrixXs dq = ADMatrixXs::Zero(nv, nv), dv = ADMatrixXs::Zero(nv, nv), da = ADMatrixXs::Zero(nv, nv);
    pinocchio::computeRNEADerivatives(ad_model, ad_data, q, v, a, dq, dv, da);
    Eigen::Map<RowAD>(ad_Y.data(), nv, nv) = dq;
    Eigen::Map<RowAD>(ad_Y.data() + nv * nv, nv, nv) = dv;
    ad_fun.Dependent(ad_X, ad_Y);
    ad_fun.optimize("no_compare_op");
  }
};

int main(int argc, char **argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: cg_export MODEL.txt OUTDIR FUNCTION...\n");
    return 2;
  }
  pinocchio::Model model;
  model.loadFromText(argv[1]);
  const std::string out = argv[2];
  for (int k = 3; k < argc; k++) {
    const std::string f = argv[k], dir = out + "/" + f, name = "cg_" + f;
    if (f == "rnea") {
      Export<pinocchio::CodeGenRNEA<double>>(model, name, f).save(dir);
    } else if (f == "crba") {
      Export<pinocchio::CodeGenCRBA<double>>(model, name, f).save(dir);
    } else if (f == "aba") {
      Export<pinocchio::CodeGenABA<double>>(model, name, f).save(dir);
    } else if (f == "minv") {
      Export<pinocchio::CodeGenMinv<double>>(model, name, f).save(dir);
    } else if (f == "rnea_derivatives") {
      Export<RneaDerivatives>(model, name, f).save(dir);
    } else if (f == "aba_derivatives") {
      Export<pinocchio::CodeGenABADerivatives<double>>(model, name, f).save(dir);
    } else {
      std::fprintf(stderr, "cg_export: unknown function %s\n", f.c_str());
      return 2;
    }
  }
  std::printf("nq %d nv %d\n", (int)model.nq, (int)model.nv);
  return 0;
}
