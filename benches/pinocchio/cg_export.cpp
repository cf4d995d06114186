// Pinocchio's own code generator, CppADCodeGen (`pinocchio/codegen/cppadcg-algo.hpp`:
// `CodeGenRNEA`, `CodeGenCRBA`, `CodeGenABA`), writing its C sources for one model (issue 30,
// the peer robovec's generated dynamics are compared with). Built and run by `cg_ops.py`.
//
//   cg_export MODEL.txt OUTDIR
//
// MODEL.txt is `model.saveToText` of `export_model.py`. Writes OUTDIR/rnea, OUTDIR/crba and
// OUTDIR/aba, each holding CppADCodeGen's library sources; the function itself is
// `cg_F_forward_zero.c` (`void cg_F_forward_zero(double const *const *in, double *const *out,
// struct LangCAtomicFun)`, in[0] = (q, v, a) / q / (q, v, tau) in Pinocchio's layout, out[0] =
// tau / M (nv x nv, column-major) / qdd). Only the zero-order forward function is generated (no
// Jacobian), as Pinocchio's `timings-cg` times it.
//
// `ModelLibraryCSourceGen::saveSources` of CppADCodeGen 2.4.3 does not compile (it calls a
// protected `getSources()` without arguments); `SaveFilesModelLibraryProcessor` writes the same
// files. `CodeGenBase` keeps its source generator protected, hence the subclass.
#include "pinocchio/codegen/cppadcg-algo.hpp"
#include "pinocchio/serialization.hpp"

#include <cstdio>
#include <string>

template<template<typename> class G>
struct Export : G<double> {
  using G<double>::G;
  void save(const std::string &dir) {
    this->build_jacobian = false;
    this->initLib();
    CppAD::cg::SaveFilesModelLibraryProcessor<double>::saveLibrarySourcesTo(*this->libcgen_ptr, dir);
  }
};

int main(int argc, char **argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: cg_export MODEL.txt OUTDIR\n");
    return 2;
  }
  pinocchio::Model model;
  model.loadFromText(argv[1]);
  const std::string out = argv[2];
  {
    Export<pinocchio::CodeGenRNEA> g(model, "cg_rnea", "rnea");
    g.save(out + "/rnea");
  }
  {
    Export<pinocchio::CodeGenCRBA> g(model, "cg_crba", "crba");
    g.save(out + "/crba");
  }
  {
    Export<pinocchio::CodeGenABA> g(model, "cg_aba", "aba");
    g.save(out + "/aba");
  }
  std::printf("nq %d nv %d\n", (int)model.nq, (int)model.nv);
  return 0;
}
