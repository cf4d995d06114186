//! The statements of a function body, shared by both ABIs: one C statement per IR value, in
//! the IR's order; the vector helpers of `batch=W`. User callbacks' names are
//! [`super::callbacks`]'s, their native statements (`abi=robotran`) [`super::native`]'s.

use std::collections::HashMap;
use std::fmt::Write as _;

use robovec_ir::{BinOp, Def, Function, Operand, TrigFn, Value};

use super::callbacks::split_callee;
use super::{is_intrinsic, CodegenC, Trig};
use crate::literal;
use robovec_ir::format::Format;
use robovec_ir::Intrinsic;

/// The default of `ROBOVEC_VBYTES`, the widest vector the compiler targets, in bytes (AVX-512:
/// 64, AVX: 32, otherwise 16: SSE2, NEON); `-DROBOVEC_VBYTES=N` chooses by hand.
const VBYTES_DEFAULT: &str = "#ifndef ROBOVEC_VBYTES\n#if defined(__AVX512F__)\n#define ROBOVEC_VBYTES 64\n\
                              #elif defined(__AVX__)\n#define ROBOVEC_VBYTES 32\n\
                              #else\n#define ROBOVEC_VBYTES 16\n#endif\n#endif\n";

/// The vector type `robovec_vec` of a batch of `lanes` states and its per-lane helpers.
///
/// The body runs on vectors of `ROBOVEC_VL` lanes — the widest the compiler targets (64 bytes
/// with AVX-512, 32 with AVX, otherwise 16: SSE2, NEON), at most `lanes` — `lanes / ROBOVEC_VL`
/// times per call (see [`chunk_loop`]). Vectors wider than the target's are lowered by the
/// compiler into pieces, which at `-O2` without `-march` made coman's `batch=8` file take
/// 35 min and 5 GB of GCC (issue 11); `-DROBOVEC_VBYTES=N` chooses the width by hand.
/// Every lane computes the same operations either way, so results are bit-identical.
///
/// The helpers are marked `ROBOVEC_UNUSED` ([`super::UNUSED_HELPERS`] defines it before them).
pub(crate) fn vector_helpers(real: &str, lanes: u32, f32: bool) -> String {
    let sfx = if f32 { "f" } else { "" };
    let size = if f32 { 4 } else { 8 };
    let mut s = format!(
        "/* {lanes} states per call: lane l of element i is in[i*{lanes} + l] (GCC/Clang vector extensions).\n \
         * The body runs on vectors of ROBOVEC_VL lanes, the widest the compiler targets (AVX-512: 64 bytes,\n \
         * AVX: 32, otherwise 16: SSE2, NEON; -DROBOVEC_VBYTES=N chooses), {lanes}/ROBOVEC_VL times per call:\n \
         * wider vectors than the target's are split by the compiler, slowly to compile and to run. */\n\
         {VBYTES_DEFAULT}\
         #define ROBOVEC_W {lanes}\n\
         #define ROBOVEC_VL (ROBOVEC_VBYTES / (int)sizeof({real}) < ROBOVEC_W ? ROBOVEC_VBYTES / (int)sizeof({real}) : ROBOVEC_W)\n\
         _Static_assert(ROBOVEC_VL >= 1 && ROBOVEC_W % ROBOVEC_VL == 0, \"ROBOVEC_VBYTES must be a power of two of at least one {real}\");\n\
         typedef {real} robovec_vec __attribute__((vector_size(ROBOVEC_VL * sizeof({real}))));\n\
         /* The bytes of one robovec_vec, for the preprocessor (intrinsics of that width). */\n\
         #define ROBOVEC_VEC_BYTES (ROBOVEC_VBYTES < ROBOVEC_W * {size} ? ROBOVEC_VBYTES : ROBOVEC_W * {size})\n\
         #if defined(__SSE2__) || defined(__AVX__)\n#include <immintrin.h>\n#endif\n"
    );
    s += &splat_helper("robovec_splat", "robovec_vec", real, "ROBOVEC_VL");
    for f in ["sin", "cos", "sqrt"] {
        let _ = writeln!(
            s,
            "static inline ROBOVEC_UNUSED robovec_vec robovec_{f}(robovec_vec x) {{ robovec_vec r; for (int lane = 0; lane < ROBOVEC_VL; lane++) r[lane] = {f}{sfx}(x[lane]); return r; }}"
        );
    }
    // One vector FMA instruction where the target has one, C99 `fma` per lane otherwise: the
    // same bits either way. Intrinsics, not a lane loop: in a large function GCC 12 neither
    // inlines nor fully vectorises the loop (serial30's `M`: 2.5x slower than without FMA).
    s += &fma_helper("robovec_fma", "robovec_vec", f32, "ROBOVEC_VEC_BYTES", "ROBOVEC_VL", false);
    s.push('\n');
    s
}

/// The vector type and helper of `slp=4` ([`super::slp`]): `robovec_v4`, four `double`s (one
/// AVX register, two SSE2 or NEON ones), and its fused multiply-add `robovec_fma4` (one
/// instruction where the target has FMA, C99 `fma` per lane otherwise: the same bits). No
/// vector crosses a function boundary (the helper takes pointers): a 32-byte vector argument
/// changes the x86-64 ABI without AVX, which GCC warns about (`-Wpsabi`).
pub(crate) fn slp_helpers() -> String {
    "/* slp=4: four isomorphic ops of one state as one op on robovec_v4 (GCC/Clang vector extensions);\n \
     * every lane computes its own scalar op, so the values are the scalar code's, bit for bit. */\n\
     typedef double robovec_v4 __attribute__((vector_size(4 * sizeof(double))));\n\
     #if defined(__FMA__) && defined(__AVX__)\n#include <immintrin.h>\n#endif\n\
     static inline ROBOVEC_UNUSED __attribute__((always_inline)) void robovec_fma4(robovec_v4 *r, const robovec_v4 *a, \
     const robovec_v4 *b, const robovec_v4 *c)\n{\n\
     #if defined(__FMA__) && defined(__AVX__)\n  *r = (robovec_v4)_mm256_fmadd_pd((__m256d)*a, (__m256d)*b, (__m256d)*c);\n\
     #else\n  for (int lane = 0; lane < 4; lane++) (*r)[lane] = fma((*a)[lane], (*b)[lane], (*c)[lane]);\n#endif\n}\n\n"
        .to_string()
}

/// True when operand `k` of fused intrinsic `i` is written negated into C's `fma`: `fms` and
/// `fnma` are `fma` of a negated operand, exactly (robovec_ir::intrinsic).
fn fma_negates(i: Intrinsic, k: usize) -> bool {
    matches!((i, k), (Intrinsic::Fms, 2) | (Intrinsic::Fnma, 0))
}

/// `static inline {ty} {name}({real} x)`: `x` in every one of the `lanes` (a macro) lanes.
fn splat_helper(name: &str, ty: &str, real: &str, lanes: &str) -> String {
    format!(
        "static inline ROBOVEC_UNUSED {ty} {name}({real} x) {{ {ty} r; for (int lane = 0; lane < {lanes}; lane++) r[lane] = x; return r; }}\n"
    )
}

/// `{name}(a, b, c)` on vectors `ty` of `float` (`f32`) or `double` whose size in bytes is the
/// macro `bytes`: one vector FMA instruction where the target has one of that width, C99 `fma`
/// per lane otherwise (the same bits either way). Intrinsics, not a lane loop: in a large
/// function GCC 12 neither inlines nor fully vectorises the loop (serial30's `M`: 2.5x slower
/// than without FMA). `halves`: a `double` vector of two registers (formats in a batch), two
/// instructions on its halves instead of the 64-byte one.
fn fma_helper(name: &str, ty: &str, f32: bool, bytes: &str, lanes: &str, halves: bool) -> String {
    let (p, x, sfx) = if f32 { ("ps", "", "f") } else { ("pd", "d", "") };
    let wide = if halves {
        format!(
            "#if defined(__AVX512F__) && {bytes} == 128\n  __m512d h[6];\n  memcpy(h, &a, 128); memcpy(h + 2, &b, 128); memcpy(h + 4, &c, 128);\n  \
             h[0] = _mm512_fmadd_pd(h[0], h[2], h[4]); h[1] = _mm512_fmadd_pd(h[1], h[3], h[5]);\n  memcpy(&a, h, 128);\n  return a;\n\
             #elif defined(__FMA__) && {bytes} == 64\n  __m256d h[6];\n  memcpy(h, &a, 64); memcpy(h + 2, &b, 64); memcpy(h + 4, &c, 64);\n  \
             h[0] = _mm256_fmadd_pd(h[0], h[2], h[4]); h[1] = _mm256_fmadd_pd(h[1], h[3], h[5]);\n  memcpy(&a, h, 64);\n  return a;\n"
        )
    } else {
        format!("#if defined(__AVX512F__) && {bytes} == 64\n  return ({ty})_mm512_fmadd_{p}((__m512{x})a, (__m512{x})b, (__m512{x})c);\n")
    };
    format!(
        "static inline ROBOVEC_UNUSED __attribute__((always_inline)) {ty} {name}({ty} a, {ty} b, {ty} c)\n{{\n{wide}\
         #elif defined(__FMA__) && {bytes} == 32\n  return ({ty})_mm256_fmadd_{p}((__m256{x})a, (__m256{x})b, (__m256{x})c);\n\
         #elif defined(__FMA__) && {bytes} == 16\n  return ({ty})_mm_fmadd_{p}((__m128{x})a, (__m128{x})b, (__m128{x})c);\n\
         #else\n  {ty} r;\n  for (int lane = 0; lane < {lanes}; lane++) r[lane] = fma{sfx}(a[lane], b[lane], c[lane]);\n  return r;\n\
         #endif\n}}\n"
    )
}

/// The name of value `index`'s copy converted to binary32 (`narrow`) or to binary64 ([`Body::converted`]).
fn converted_name(index: usize, narrow: bool) -> String {
    format!("robovec_{}{index}", if narrow { 'f' } else { 'd' })
}

/// The vector type of a batch's binary32 values (`narrow`) or of its other values.
fn vector_type(narrow: bool) -> &'static str {
    if narrow {
        "robovec_vec32"
    } else {
        "robovec_vec"
    }
}

/// The vector types of a batch of `lanes` states in a file whose values carry numeric formats
/// ([`robovec_ir::format`], `precision=f64`): `robovec_vec32` of `float` for binary32 values and
/// `robovec_vec` of `double` for the others, both of `ROBOVEC_VL` lanes, the lanes of the widest
/// `float` vector the compiler targets (8 with AVX2): a binary32 op is one instruction on a
/// full register, a binary64 one two (the compiler splits a `double` vector wider than the
/// target's). Their per-lane helpers (sin, cos, sqrt and fma of both types; the fused ones as
/// vector FMA instructions where the target has them, split in halves for the `double`
/// vector of twice the register), `robovec_veci` of `int64_t` for fixed-point values' integers
/// and `robovec_fix_from_v`, a batch's store in `fix<w,f>`.
pub(crate) fn format_vector_helpers(lanes: u32) -> String {
    let mut s = format!(
        "/* {lanes} states per call: lane l of element i is in[i*{lanes} + l] (GCC/Clang vector extensions).\n \
         * The values carry numeric formats: binary32 ones are robovec_vec32 (float), the others robovec_vec\n \
         * (double), both of ROBOVEC_VL lanes: the lanes of the widest float vector the compiler targets\n \
         * (AVX-512: 64 bytes, AVX: 32, otherwise 16; -DROBOVEC_VBYTES=N chooses), {lanes}/ROBOVEC_VL times per call. */\n\
         {VBYTES_DEFAULT}\
         #define ROBOVEC_W {lanes}\n\
         #define ROBOVEC_VL (ROBOVEC_VBYTES / 4 < ROBOVEC_W ? ROBOVEC_VBYTES / 4 : ROBOVEC_W)\n\
         _Static_assert(ROBOVEC_VL >= 1 && ROBOVEC_W % ROBOVEC_VL == 0, \"ROBOVEC_VBYTES must be a power of two of at least one float\");\n\
         typedef double robovec_vec __attribute__((vector_size(ROBOVEC_VL * 8)));\n\
         typedef float robovec_vec32 __attribute__((vector_size(ROBOVEC_VL * 4)));\n\
         /* The bytes of one robovec_vec and of one robovec_vec32, for the preprocessor. */\n\
         #define ROBOVEC_VEC_BYTES (ROBOVEC_VBYTES < ROBOVEC_W * 4 ? 2 * ROBOVEC_VBYTES : ROBOVEC_W * 8)\n\
         #define ROBOVEC_VEC32_BYTES (ROBOVEC_VBYTES < ROBOVEC_W * 4 ? ROBOVEC_VBYTES : ROBOVEC_W * 4)\n\
         /* Half a robovec_vec (trig=inline's double code runs on halves: one register each). */\n\
         #define ROBOVEC_HL (ROBOVEC_VL / 2)\n\
         typedef double robovec_vech __attribute__((vector_size(ROBOVEC_HL * 8)));\n\
         #define ROBOVEC_VECH_BYTES (ROBOVEC_HL * 8)\n\
         #if defined(__SSE2__) || defined(__AVX__)\n#include <immintrin.h>\n#endif\n"
    );
    for (ty, sfx, real) in [("robovec_vec", "", "double"), ("robovec_vec32", "32", "float")] {
        let f = if sfx.is_empty() { "" } else { "f" };
        s += &splat_helper(&format!("robovec_splat{sfx}"), ty, real, "ROBOVEC_VL");
        for fun in ["sin", "cos", "sqrt"] {
            let _ = writeln!(
                s,
                "static inline ROBOVEC_UNUSED {ty} robovec_{fun}{sfx}({ty} x) {{ {ty} r; for (int lane = 0; lane < ROBOVEC_VL; lane++) r[lane] = {fun}{f}(x[lane]); return r; }}"
            );
        }
    }
    // Vector FMA instructions as in `vector_helpers`; a `double` vector of two registers in halves.
    s += &fma_helper("robovec_fma32", "robovec_vec32", true, "ROBOVEC_VEC32_BYTES", "ROBOVEC_VL", false);
    s += &fma_helper("robovec_fma", "robovec_vec", false, "ROBOVEC_VEC_BYTES", "ROBOVEC_VL", true);
    let _ = write!(
        s,
        "/* A binary32 input's lanes from the double array, an output's lanes into it: by 32- or 16-byte\n \
         * instructions where the vector is one such register (no 64-byte double vector on an AVX-512 machine,\n \
         * whose wide instructions lower the clock), lane by lane otherwise. */\n\
         static inline ROBOVEC_UNUSED __attribute__((always_inline)) robovec_vec32 robovec_load32(const double *p)\n{{\n\
         #if defined(__AVX__) && ROBOVEC_VEC32_BYTES == 32\n  \
         return (robovec_vec32)_mm256_set_m128(_mm256_cvtpd_ps(_mm256_loadu_pd(p + 4)), _mm256_cvtpd_ps(_mm256_loadu_pd(p)));\n\
         #elif defined(__SSE2__) && ROBOVEC_VEC32_BYTES == 16\n  \
         return (robovec_vec32)_mm_movelh_ps(_mm_cvtpd_ps(_mm_loadu_pd(p)), _mm_cvtpd_ps(_mm_loadu_pd(p + 2)));\n\
         #else\n  robovec_vec32 r;\n  for (int lane = 0; lane < ROBOVEC_VL; lane++) r[lane] = (float)p[lane];\n  return r;\n\
         #endif\n}}\n\
         static inline ROBOVEC_UNUSED __attribute__((always_inline)) void robovec_store32(double *p, robovec_vec32 x)\n{{\n\
         #if defined(__AVX__) && ROBOVEC_VEC32_BYTES == 32\n  \
         _mm256_storeu_pd(p, _mm256_cvtps_pd(_mm256_castps256_ps128((__m256)x)));\n  \
         _mm256_storeu_pd(p + 4, _mm256_cvtps_pd(_mm256_extractf128_ps((__m256)x, 1)));\n\
         #elif defined(__SSE2__) && ROBOVEC_VEC32_BYTES == 16\n  \
         _mm_storeu_pd(p, _mm_cvtps_pd((__m128)x));\n  _mm_storeu_pd(p + 2, _mm_cvtps_pd(_mm_movehl_ps((__m128)x, (__m128)x)));\n\
         #else\n  for (int lane = 0; lane < ROBOVEC_VL; lane++) p[lane] = (double)x[lane];\n\
         #endif\n}}\n"
    );
    s += &splat_helper("robovec_splath", "robovec_vech", "double", "ROBOVEC_HL");
    s += &fma_helper("robovec_fmah", "robovec_vech", false, "ROBOVEC_VECH_BYTES", "ROBOVEC_HL", false);
    let _ = writeln!(
        s,
        "/* Fixed-point values' integers (robovec_ir::format::integer_op), one 64-bit lane per state; a double\n \
         * result stored in fix<w,f> lane by lane (robovec_fix_from, s = 2^f). */\n\
         typedef int64_t robovec_veci __attribute__((vector_size(ROBOVEC_VL * 8)));\n\
         static inline ROBOVEC_UNUSED robovec_veci robovec_fix_from_v(robovec_vec x, double s) {{ robovec_veci r; for (int lane = 0; lane < ROBOVEC_VL; lane++) r[lane] = robovec_fix_from(x[lane], s); return r; }}"
    );
    s.push('\n');
    s
}

/// The loop of a batched body over its chunks of `ROBOVEC_VL` lanes (see [`vector_helpers`]):
/// lane `l` of chunk `robovec_chunk` is state `robovec_chunk*ROBOVEC_VL + l`.
pub(crate) const CHUNK_LOOP: &str =
    "  for (int robovec_chunk = 0; robovec_chunk < ROBOVEC_W / ROBOVEC_VL; robovec_chunk++) {\n";

/// The native form of a function's user callbacks (`abi=robotran`), which
/// [`super::native::statements`] writes and [`Body`] places.
pub(crate) struct Native {
    /// Value index → its C statements (declaration of the value included).
    pub statements: HashMap<usize, String>,
    /// A later element of a vector callback instance → the instance's first element, whose
    /// statements make the native call that this element reads.
    pub lead: HashMap<usize, Value>,
}

/// Writes the statements of one function body.
pub(crate) struct Body<'a> {
    pub o: &'a CodegenC,
    pub f: &'a Function,
    /// C name of every value.
    pub names: &'a [String],
    /// `abi=robotran`: the statements of every user callback value (native signatures,
    /// [`super::native::statements`]); `None`: the adapter form of both ABIs' plain code.
    pub native: Option<&'a Native>,
    /// `trig=inline`: value index → (its partner, true when this value's statement computes
    /// both); see [`fused_trig`].
    fused: HashMap<usize, (Value, bool)>,
    /// `trig=inline`, one state: the trig values computed together at the start; see
    /// [`TrigBlock`].
    block: Option<TrigBlock>,
    /// `-time-limit`: one tick per statement written; once it says stop, no more statements
    /// are written and the caller fails with [`robovec_passes::PassError::TimeLimit`].
    ticker: &'a robovec_passes::Ticker,
    /// By value index: no op reads the value and no output is it (a value Robotran computes and
    /// never uses, before `dce`). Its statement is followed by `(void)NAME;`, so that
    /// `-Wall -Werror` builds pass (`-Wunused-variable`).
    unused: Vec<bool>,
    /// A batch with formats: (value index, to binary32) of the operands already converted in the
    /// statements written by this [`Body::statements_with`] call, whose converted copy
    /// (`robovec_f{index}`, `robovec_d{index}`) later reads use: one conversion per value and
    /// direction per part, not one per use (bit-identical: a conversion is a function of the value).
    converted: std::cell::RefCell<std::collections::HashSet<(usize, bool)>>,
    /// Some value has a numeric format ([`Function::has_formats`], read once: it scans the values).
    formats: bool,
    /// `slp=4`, one state of doubles without formats: the packs of [`super::slp`] (empty otherwise).
    packs: super::slp::Packs,
    /// The packs written by this [`Body::statements_with`] call (a part): a later pack of the
    /// same part reads them as vectors, one of a later part gathers their members.
    written: std::cell::RefCell<std::collections::HashSet<usize>>,
}

impl<'a> Body<'a> {
    /// The body writer of `f` under `o`, with the values' C names and (`abi=robotran`) the
    /// native callback statements.
    pub fn new(
        o: &'a CodegenC,
        f: &'a Function,
        names: &'a [String],
        native: Option<&'a Native>,
        ticker: &'a robovec_passes::Ticker,
    ) -> Body<'a> {
        let fused = if o.trig == Trig::Inline { fused_trig(f) } else { HashMap::new() };
        let block = if o.trig == Trig::Inline && o.batch == 1 { TrigBlock::of(f) } else { None };
        let unused = f.use_counts().iter().map(|&n| n == 0).collect();
        let formats = f.has_formats();
        let packs = if o.slp > 0 && o.batch == 1 && !o.f32() && !formats {
            super::slp::Packs::find(f)
        } else {
            super::slp::Packs::default()
        };
        Body {
            o,
            f,
            names,
            native,
            fused,
            block,
            ticker,
            unused,
            converted: Default::default(),
            formats,
            packs,
            written: Default::default(),
        }
    }

    /// The values that have a statement, in the order they are written, and for each whether
    /// it is *attached* to the value before it. The order is the body's, except that a value
    /// another value's statement computes (the second of a fused sin/cos pair with
    /// `trig=inline`) or that reads another's native call (a later element of an `abi=robotran`
    /// callback instance, [`super::native`]) is attached: it follows that value at once. Such a
    /// value has the same operands as the one it follows, which come before both, so the order
    /// stays topological. Trig values are left out with `trig=input` (they are inputs). A
    /// function split into parts ([`super::split`]) is never cut before an attached value.
    /// The members of a [`TrigBlock`] come first, all attached to the first one (they read
    /// inputs only). Linear in the body.
    pub fn order(&self) -> (Vec<Value>, Vec<bool>) {
        let mut followers: HashMap<usize, Vec<Value>> = HashMap::new();
        let mut follows = vec![false; self.f.values.len()];
        let mut order = Vec::with_capacity(self.f.body.len());
        let mut attached = Vec::with_capacity(self.f.body.len());
        if let Some(b) = &self.block {
            for &v in &b.members {
                follows[v.index()] = true;
                attached.push(!order.is_empty());
                order.push(v);
            }
        }
        let leads = self
            .fused
            .iter()
            .filter(|(v, &(_, leads))| !leads && !self.block.as_ref().is_some_and(|b| b.slot_of.contains_key(*v)))
            .map(|(&v, &(lead, _))| (v, lead))
            .chain(self.native.iter().flat_map(|n| n.lead.iter().map(|(&v, &lead)| (v, lead))));
        for (v, lead) in leads {
            follows[v] = true;
            followers.entry(lead.index()).or_default().push(Value::with_number(v as u32));
        }
        let position: HashMap<usize, usize> = if followers.is_empty() {
            HashMap::new()
        } else {
            self.f.body.iter().enumerate().map(|(p, v)| (v.index(), p)).collect()
        };
        for &v in &self.f.body {
            if follows[v.index()] || (self.o.trig == Trig::Input && matches!(self.f.value(v).def, Def::Trig(..))) {
                continue;
            }
            order.push(v);
            attached.push(false);
            if let Some(fs) = followers.get_mut(&v.index()) {
                fs.sort_by_key(|w| position[&w.index()]);
                for &w in fs.iter() {
                    order.push(w);
                    attached.push(true);
                }
            }
        }
        if self.packs.members.is_empty() {
            return (order, attached);
        }
        // `slp`: a pack's members together where its last member was, lane 0 first, the others
        // attached (never cut apart by a part boundary).
        let mut last = vec![usize::MAX; self.packs.members.len()];
        for (p, v) in order.iter().enumerate() {
            if let Some(&(id, _)) = self.packs.of.get(&v.index()) {
                last[id] = p;
            }
        }
        let (mut packed, mut packed_attached) = (Vec::with_capacity(order.len()), Vec::with_capacity(order.len()));
        for (p, (v, a)) in order.into_iter().zip(attached).enumerate() {
            match self.packs.of.get(&v.index()) {
                Some(&(id, _)) if last[id] == p => {
                    for (l, &w) in self.packs.members[id].iter().enumerate() {
                        packed.push(w);
                        packed_attached.push(l > 0);
                    }
                }
                Some(_) => {}
                None => {
                    packed.push(v);
                    packed_attached.push(a);
                }
            }
        }
        (packed, packed_attached)
    }

    /// `slp`: the statements of pack `id` (one vector op on its operands as vectors, then its
    /// members as scalars), written at its lane 0. An operand position whose four operands are
    /// a pack written earlier in this part, lane for lane, reads that vector (negated, or times
    /// a vector of signs, where lanes read it negated: exact); four equal ones are one scalar
    /// (spread over the lanes by the vector extensions), other ones are gathered (a compound
    /// literal).
    fn write_pack(&self, s: &mut String, id: usize) {
        use super::slp::{Arg, PackOp};
        let members = &self.packs.members[id];
        let shape = &self.packs.shapes[id];
        let pack = format!("robovec_p{}", members[0].index());
        // The pack written earlier in this part whose members are `g` lane for lane.
        let earlier = |g: &[Operand]| -> Option<String> {
            let q = self.packs.whole(g).filter(|q| self.written.borrow().contains(q))?;
            Some(format!("robovec_p{}", self.packs.members[q][0].index()))
        };
        let lanes = |g: &[Arg]| -> String {
            let one = |a: &Arg| match (a.x, a.neg) {
                (Operand::Const(c), true) => self.read(&Operand::Const(-c), false),
                (x, true) => format!("-{}", self.read(&x, false)),
                (x, false) => self.read(&x, false),
            };
            format!("(robovec_v4){{{}}}", g.iter().map(one).collect::<Vec<_>>().join(", "))
        };
        match shape.op {
            PackOp::Binary(op) => {
                let op = match op {
                    BinOp::Add => '+',
                    BinOp::Sub => '-',
                    BinOp::Mul => '*',
                    BinOp::Div => '/',
                };
                let (a, b) = (shape.operands(0), shape.operands(1));
                let same = |g: &[Operand]| g.iter().all(|x| *x == g[0]);
                // A scalar with a vector is spread over the lanes (two scalars would be one value).
                let side = |k: usize, g: &[Operand], scalar_ok: bool| {
                    earlier(g).unwrap_or_else(|| {
                        if scalar_ok && same(g) {
                            self.read(&g[0], false)
                        } else {
                            lanes(&shape.args[k])
                        }
                    })
                };
                let expr = format!("{} {op} {}", side(0, &a, true), side(1, &b, !same(&a)));
                let _ = writeln!(s, "  const robovec_v4 {pack} = {expr};");
            }
            PackOp::Fma | PackOp::MulAdd => {
                let mut args = Vec::with_capacity(3);
                for k in 0..3 {
                    let g = &shape.args[k];
                    let arg = match earlier(&shape.operands(k)) {
                        Some(name) if g.iter().all(|a| a.neg) => {
                            let _ = writeln!(s, "  const robovec_v4 {pack}_n{k} = -{name};");
                            format!("{pack}_n{k}")
                        }
                        Some(name) if g.iter().any(|a| a.neg) => {
                            let signs: Vec<&str> = g.iter().map(|a| if a.neg { "-1.0" } else { "1.0" }).collect();
                            let _ = writeln!(
                                s,
                                "  const robovec_v4 {pack}_n{k} = {name} * (robovec_v4){{{}}};",
                                signs.join(", ")
                            );
                            format!("{pack}_n{k}")
                        }
                        Some(name) => name,
                        None => lanes(g),
                    };
                    args.push(arg);
                }
                if shape.op == PackOp::Fma {
                    let args: Vec<String> = args.iter().map(|a| format!("&{a}")).collect();
                    let _ = writeln!(s, "  robovec_v4 {pack};\n  robovec_fma4(&{pack}, {});", args.join(", "));
                } else {
                    let _ = writeln!(s, "  const robovec_v4 {pack} = {} * {} + {};", args[0], args[1], args[2]);
                }
            }
        }
        for (l, &m) in members.iter().enumerate() {
            let _ = writeln!(s, "  ROBOVEC_UNUSED const double {} = {pack}[{l}];", self.names[m.index()]);
        }
        self.written.borrow_mut().insert(id);
    }

    /// An operand as a C expression (a constant exact in the precision: [`literal::operand`]),
    /// as an op that does not narrow reads it ([`Body::read`]).
    pub fn operand(&self, x: &Operand) -> String {
        self.read(x, false)
    }

    /// True when `v` is computed in binary32 in a file of `precision=f64` ([`robovec_ir::format`]):
    /// a `float` temporary (a `robovec_vec32` in a batch).
    pub fn narrow(&self, v: Value) -> bool {
        self.f.format(v) == Format::Binary32
    }

    /// `x` as an op reads it: `narrow` (the op's value is binary32) rounds a constant to a
    /// `float` literal and converts a value of another format to `float`; an op that does not
    /// narrow reads a binary32 value widened to `double` (exact). A fixed-point value, held as
    /// its integer `k`, reads as `k · 2^-f` in `double` (exact: `w ≤ 53`), then `float`. A batch
    /// converts whole vectors (`__builtin_convertvector`). (An integer op reads fixed-point
    /// integers as they are: [`Body::integer_expr`].)
    pub fn read(&self, x: &Operand, narrow: bool) -> String {
        match x {
            Operand::Const(c) => literal::operand(*c, narrow || self.o.f32()),
            Operand::Value(w) => {
                let n = &self.names[w.index()];
                let vec = self.o.batch > 1;
                let fix = self.fix_unit(*w);
                if fix.is_none() && self.narrow(*w) == narrow {
                    n.clone()
                } else if self.converted.borrow().contains(&(w.index(), narrow)) {
                    converted_name(w.index(), narrow)
                } else if let Some(unit) = fix {
                    let d = if vec {
                        format!("(__builtin_convertvector({n}, robovec_vec) * {unit})")
                    } else {
                        format!("((double){n} * {unit})")
                    };
                    match (narrow, vec) {
                        (false, _) => d,
                        (true, true) => format!("__builtin_convertvector({d}, robovec_vec32)"),
                        (true, false) => format!("(float){d}"),
                    }
                } else if vec {
                    format!("__builtin_convertvector({n}, {})", vector_type(narrow))
                } else {
                    format!("({}){n}", if narrow { "float" } else { "double" })
                }
            }
        }
    }

    /// [`Body::read`] as a value of the op's type (a constant is splat in a batch).
    pub fn read_value(&self, x: &Operand, narrow: bool) -> String {
        match x {
            Operand::Const(_) if self.o.batch > 1 => {
                format!("robovec_splat{}({})", if narrow { "32" } else { "" }, self.read(x, narrow))
            }
            _ => self.read(x, narrow),
        }
    }

    /// `expr`, of the file's real type (`double`, or `robovec_vec` in a batch), as a value of
    /// `v`'s format ([`robovec_ir::format`]): itself for binary64, converted to `float` (to
    /// `robovec_vec32`) for binary32, the integer `robovec_fix_from(expr, 2^f)`
    /// (`robovec_fix_from_v` in a batch) for `fix<w,f>` (the file's
    /// [`super::file::FORMAT_HELPERS`]).
    pub fn stored(&self, v: Value, expr: String) -> String {
        let vec = self.o.batch > 1;
        match self.f.format(v) {
            Format::Binary64 => expr,
            Format::Binary32 if vec => format!("__builtin_convertvector({expr}, robovec_vec32)"),
            Format::Binary32 => format!("(float)({expr})"),
            Format::Fix { fraction, .. } => {
                let scale = literal::operand(2f64.powi(fraction), false);
                if vec {
                    format!("robovec_fix_from_v({expr}, {scale})")
                } else {
                    format!("({})robovec_fix_from({expr}, {scale})", self.type_of(v))
                }
            }
        }
    }

    /// For a fixed-point value (held as its integer `k`), the `double` literal `2^-f` that
    /// scales it to its value; `None` for a binary one.
    fn fix_unit(&self, v: Value) -> Option<String> {
        match self.f.format(v) {
            Format::Fix { fraction, .. } => Some(literal::operand(2f64.powi(-fraction), false)),
            _ => None,
        }
    }

    /// The C expression of an integer op ([`robovec_ir::format::integer_op`]) of the
    /// fixed-point value `v`: its terms on the operands' integers, aligned by multiplying by
    /// powers of two, summed, then rounded by `robovec_fix_shr` (`floor(x / 2^n)`, portable)
    /// after adding half a step: bit for bit `IntegerOp::eval`. One state: in `int32_t` when the
    /// whole intermediate fits 31 bits (a 32-bit microcontroller's word: `|K| ≤ 2^30`, a half
    /// step at most 2^29), else `int64_t` (`|K| ≤ 2^62`, a half step at most 2^61); a batch: `robovec_veci` vectors of `int64_t`, its shift GCC's and
    /// Clang's arithmetic `>>` of vectors.
    fn integer_expr(&self, op: &robovec_ir::format::IntegerOp) -> String {
        use robovec_ir::format::IntFactor;
        let vec = self.o.batch > 1;
        // |K| ≤ 2^30 and a half step ≤ 2^29: below 2^31.
        let small = !vec && op.bits <= 30 && op.shift <= 30;
        let t = if small { "int32_t" } else { "int64_t" };
        let power = |n: i32| format!("(({t})1 << {n})");
        let mut sum = String::new();
        for (i, term) in op.terms.iter().enumerate() {
            let factors: Vec<String> = term
                .factors
                .iter()
                .map(|x| match *x {
                    IntFactor::Value { value, .. } if vec => self.names[value.index()].clone(),
                    IntFactor::Value { value, .. } => format!("({t}){}", self.names[value.index()]),
                    IntFactor::Const { mantissa, .. } => format!("(({t})({mantissa}))"),
                })
                .collect();
            let mut e = factors.join(" * ");
            let align = op.fraction - term.fraction();
            if align > 0 {
                e = format!("{e} * {}", power(align));
            }
            match (i, term.negative) {
                (0, false) => sum += &e,
                (0, true) => sum += &format!("-({e})"),
                (_, false) => sum += &format!(" + {e}"),
                (_, true) => sum += &format!(" - {e}"),
            }
        }
        match op.shift {
            0 => sum,
            s if s > 0 && vec => format!("(({sum} + {}) >> {s})", power(s - 1)),
            s if s > 0 => format!("robovec_fix_shr{}({sum} + {}, {s})", if small { "32" } else { "" }, power(s - 1)),
            s => format!("(({sum}) * {})", power(-s)),
        }
    }

    /// The type of the file's real values: `double`, `float` or `robovec_vec`.
    pub fn value_type(&self) -> &'static str {
        if self.o.batch > 1 {
            "robovec_vec"
        } else {
            self.o.real()
        }
    }

    /// The C type of `v`: [`Body::value_type`], or `float` (`robovec_vec32`) for a binary32
    /// value; for a fixed-point value its integer `k` (the value is `k · 2^-f`): `int32_t` up to
    /// 32 bits, `int64_t` above (`robovec_veci`, 64-bit lanes, in a batch).
    pub fn type_of(&self, v: Value) -> &'static str {
        match (self.f.format(v), self.o.batch > 1) {
            (Format::Fix { .. }, true) => "robovec_veci",
            (Format::Fix { width, .. }, false) if width <= 32 => "int32_t",
            (Format::Fix { .. }, false) => "int64_t",
            (Format::Binary32, true) => "robovec_vec32",
            (Format::Binary32, false) => "float",
            (Format::Binary64, _) => self.value_type(),
        }
    }

    /// An operand as a value of [`Body::value_type`] (a constant is splat in a batch).
    pub fn operand_value(&self, x: &Operand) -> String {
        self.read_value(x, false)
    }

    /// The statements of `order` (a slice of [`Body::order`] that never starts with an
    /// attached value), calling `before(s, v)` just before and `after(s, v)` just after the
    /// statement of each value `v` (the plain ABI reads inputs at their first use and writes
    /// outputs as soon as they are computed; a split function also reads and writes its live
    /// values there). The statement of an attached trig value is empty: the value before it
    /// declared both. The members of a [`TrigBlock`] (always in one slice: they are attached)
    /// have one statement, at the last member, that computes them all; `after` of each runs
    /// after it. Stops early, the text incomplete, when the ticker says stop.
    pub fn statements_with(
        &self,
        order: &[Value],
        s: &mut String,
        before: &mut dyn FnMut(&mut String, Value),
        after: &mut dyn FnMut(&mut String, Value),
    ) {
        let real_ty = self.value_type();
        let vec = self.o.batch > 1;
        let sfx = if self.o.f32() { "f" } else { "" };
        // Members of the trig block whose `after` waits for the block's statement.
        let mut waiting: Vec<Value> = Vec::new();
        self.converted.borrow_mut().clear();
        self.written.borrow_mut().clear();
        // `slp`: members of the pack just written, which follow its lane 0 in `order`.
        let mut skip = 0;
        for &v in order {
            if skip > 0 {
                skip -= 1;
                continue;
            }
            if self.ticker.tick() {
                return;
            }
            let name = &self.names[v.index()];
            let def = &self.f.value(v).def;
            before(s, v);
            if let Some(&(id, 0)) = self.packs.of.get(&v.index()) {
                let members = self.packs.members[id];
                for &w in &members[1..] {
                    before(s, w);
                }
                self.write_pack(s, id);
                for &w in &members {
                    self.mark_unused(s, w);
                    after(s, w);
                }
                skip = members.len() - 1;
                continue;
            }
            // Not for callbacks (lane by lane) nor robovec's sin/cos (their own reads).
            // Nor integer ops: they read the fixed-point integers as they are.
            let integer = self.integer_op(v);
            let own_reads = matches!(def, Def::Call(c, a) if !is_intrinsic(c, a.len()))
                || (matches!(def, Def::Trig(..)) && self.o.trig == Trig::Inline)
                || integer.is_some();
            if vec && self.formats && !own_reads {
                self.convert_operands(s, v);
            }
            if let Some(b) = self.block.as_ref().filter(|b| b.slot_of.contains_key(&v.index())) {
                waiting.push(v);
                if b.members.last() == Some(&v) {
                    b.write(self, s);
                    for &w in &waiting {
                        self.mark_unused(s, w);
                        after(s, w);
                    }
                }
                continue;
            }
            let ty = self.type_of(v);
            let narrow = self.narrow(v);
            if let Some(op) = integer {
                let _ = writeln!(s, "  const {ty} {name} = ({ty})({});", self.integer_expr(&op));
                self.mark_unused(s, v);
                after(s, v);
                continue;
            }
            match def {
                Def::Input | Def::Expr(_) => unreachable!("atomised bodies hold trig, binary ops and calls"),
                Def::Trig(..) if self.fused.get(&v.index()).is_some_and(|&(_, leads)| !leads) => {} // with its partner
                Def::Trig(t, a) if self.o.trig == Trig::Inline => {
                    // robovec's sin/cos compute in the file's real type, then convert; binary32
                    // values of a batch in binary32 (`robovec_sincos_inline32`, trig::helpers_vec32).
                    let arg = self.read(&Operand::Value(*a), false);
                    let partner = self.fused.get(&v.index()).map(|&(other, _)| other);
                    let all32 = vec && narrow && partner.is_none_or(|p| self.narrow(p));
                    if let Some(other) = partner {
                        let (sin, cos) = if *t == TrigFn::Sin { (v, other) } else { (other, v) };
                        let (sn, cn) = (&self.names[sin.index()], &self.names[cos.index()]);
                        if all32 {
                            let arg = self.read(&Operand::Value(*a), true);
                            let _ = writeln!(
                                s,
                                "  robovec_vec32 {sn}, {cn};\n  robovec_sincos_inline32({arg}, &{sn}, &{cn});"
                            );
                        } else if self.f.format(sin).is_default() && self.f.format(cos).is_default() {
                            let _ =
                                writeln!(s, "  {real_ty} {sn}, {cn};\n  robovec_sincos_inline({arg}, &{sn}, &{cn});");
                        } else {
                            let _ = writeln!(
                                s,
                                "  {} {sn};\n  {} {cn};\n  {{\n    {real_ty} robovec_s, robovec_c;\n    \
                                 robovec_sincos_inline({arg}, &robovec_s, &robovec_c);\n    {sn} = {};\n    {cn} = {};\n  }}",
                                self.type_of(sin),
                                self.type_of(cos),
                                self.stored(sin, "robovec_s".into()),
                                self.stored(cos, "robovec_c".into()),
                            );
                            // Assigned, not passed by address: an unread one needs its (void).
                            for w in [sin, cos] {
                                if self.unused[w.index()] {
                                    let _ = writeln!(s, "  (void){};", self.names[w.index()]);
                                }
                            }
                        }
                    } else {
                        let fun = if *t == TrigFn::Sin { "sin" } else { "cos" };
                        let expr = if all32 {
                            format!("robovec_{fun}_inline32({})", self.read(&Operand::Value(*a), true))
                        } else {
                            self.stored(v, format!("robovec_{fun}_inline({arg})"))
                        };
                        let _ = writeln!(s, "  const {ty} {name} = {expr};");
                    }
                }
                Def::Trig(t, a) => {
                    let fun = match t {
                        TrigFn::Sin => "sin",
                        TrigFn::Cos => "cos",
                    };
                    let arg = self.read(&Operand::Value(*a), narrow);
                    let expr = match (vec, narrow) {
                        (true, true) => format!("robovec_{fun}32({arg})"),
                        (false, true) => format!("{fun}f({arg})"),
                        (true, false) => self.stored(v, format!("robovec_{fun}({arg})")),
                        (false, false) => self.stored(v, format!("{fun}{sfx}({arg})")),
                    };
                    let _ = writeln!(s, "  const {ty} {name} = {expr};");
                }
                Def::Binary(op, a, b) => {
                    let op = match op {
                        BinOp::Add => '+',
                        BinOp::Sub => '-',
                        BinOp::Mul => '*',
                        BinOp::Div => '/',
                    };
                    // Scalar with vector is fine in a batch; two constants need one splat.
                    let a = if matches!((a, b), (Operand::Const(_), Operand::Const(_))) {
                        self.read_value(a, narrow)
                    } else {
                        self.read(a, narrow)
                    };
                    let expr = format!("{a} {op} {}", self.read(b, narrow));
                    let expr = if narrow { expr } else { self.stored(v, expr) };
                    let _ = writeln!(s, "  const {ty} {name} = {expr};");
                }
                Def::Call(c, args) if is_intrinsic(c, args.len()) => {
                    let i = Intrinsic::of(c, args.len()).expect("checked");
                    let neg = |k: usize| fma_negates(i, k);
                    let list: Vec<String> = args
                        .iter()
                        .enumerate()
                        .map(|(k, x)| match (x, neg(k)) {
                            (Operand::Const(c), true) => self.read_value(&Operand::Const(-c), narrow),
                            (_, true) => format!("-{}", self.read_value(x, narrow)),
                            (_, false) => self.read_value(x, narrow),
                        })
                        .collect();
                    let callee = if i == Intrinsic::Sqrt { "sqrt" } else { "fma" };
                    let callee = match (vec, narrow) {
                        (true, true) => format!("robovec_{callee}32"),
                        (false, true) => format!("{callee}f"),
                        (true, false) => format!("robovec_{callee}"),
                        (false, false) => format!("{callee}{sfx}"),
                    };
                    let expr = format!("{callee}({})", list.join(", "));
                    let expr = if narrow { expr } else { self.stored(v, expr) };
                    let _ = writeln!(s, "  const {ty} {name} = {expr};");
                }
                Def::Call(..) if self.native.is_some() => {
                    s.push_str(&self.native.expect("checked").statements[&v.index()]);
                }
                Def::Call(c, args) => {
                    // A callback computes in binary64 on its operands as the op reads them.
                    let (base, idx) = split_callee(c).expect("checked by callbacks()");
                    let lane = |x: &Operand| match x {
                        Operand::Value(w) if vec => {
                            let n = format!("{}[lane]", self.names[w.index()]);
                            let n = match self.fix_unit(*w) {
                                Some(unit) => format!("((double){n} * {unit})"),
                                None => n,
                            };
                            if narrow && !self.narrow(*w) {
                                format!("(float){n}")
                            } else {
                                n
                            }
                        }
                        _ => self.read(x, narrow),
                    };
                    let list: Vec<String> = args.iter().map(lane).collect();
                    let argv = if list.is_empty() {
                        format!("(const {} *)0", self.o.real())
                    } else {
                        format!("(const {}[]){{{}}}", self.o.real(), list.join(", "))
                    };
                    let idx: String = idx.iter().map(|i| format!("{i}, ")).collect();
                    let call = format!("{base}({idx}{}, {}, {argv})", c.elem.unwrap_or(0), args.len());
                    if vec {
                        let one = match self.f.format(v) {
                            Format::Binary64 => call,
                            Format::Binary32 => format!("(float)({call})"),
                            Format::Fix { fraction, .. } => {
                                format!("robovec_fix_from({call}, {})", literal::operand(2f64.powi(fraction), false))
                            }
                        };
                        let _ = writeln!(
                            s,
                            "  {ty} {name};\n  for (int lane = 0; lane < ROBOVEC_VL; lane++) {name}[lane] = {one};"
                        );
                    } else {
                        let _ = writeln!(s, "  const {ty} {name} = {};", self.stored(v, call));
                    }
                }
            }
            self.mark_unused(s, v);
            after(s, v);
        }
    }

    /// A batch with formats: the converted copy of each operand of `v`'s op read in another
    /// format than the op computes in, written once per [`Body::statements_with`] call (see
    /// [`Body::converted`]) just before the first statement that reads it.
    fn convert_operands(&self, s: &mut String, v: Value) {
        let narrow = self.narrow(v);
        self.f.value(v).def.for_each_value(|w| {
            let same = self.fix_unit(w).is_none() && self.narrow(w) == narrow;
            if same || self.converted.borrow().contains(&(w.index(), narrow)) {
                return;
            }
            let expr = self.read(&Operand::Value(w), narrow);
            let _ = writeln!(s, "  const {} {} = {expr};", vector_type(narrow), converted_name(w.index(), narrow));
            self.converted.borrow_mut().insert((w.index(), narrow));
        });
    }

    /// `v`'s integer op, when its value is fixed point and its op is one (only in a function
    /// with formats: the check reads `v`'s format).
    fn integer_op(&self, v: Value) -> Option<robovec_ir::format::IntegerOp> {
        if self.formats {
            robovec_ir::format::integer_op(self.f, v)
        } else {
            None
        }
    }

    /// `(void)NAME;` after the statement of a value nothing reads ([`Body::unused`]); the
    /// second of a fused sin/cos pair is declared with its partner, whose statement says so.
    fn mark_unused(&self, s: &mut String, v: Value) {
        if self.unused[v.index()] && self.fused.get(&v.index()).is_none_or(|&(_, leads)| leads) {
            let _ = writeln!(s, "  (void){};", self.names[v.index()]);
        }
    }
}

/// `trig=inline` with one state: the `sin` and `cos` values of inputs (the joint coordinates),
/// computed together by one call of `robovec_sincos_n` ([`super::trig::helpers`]) at the start
/// of the body, a loop the C compiler vectorises: on Talos's RNEA (32 coordinates, AVX2) 35 %
/// less time than one `robovec_sincos_inline` per coordinate, whose reductions and polynomials
/// are latency chains. The same bits as those calls. Only with two coordinates or more.
struct TrigBlock {
    /// The trig values, in body order.
    members: Vec<Value>,
    /// The arguments, one per slot of the block's arrays, in order of first use.
    args: Vec<Value>,
    /// Trig value index → (slot, true for `sin`).
    slot_of: HashMap<usize, (usize, bool)>,
}

impl TrigBlock {
    /// The block of `f`'s trig values whose argument is an input, if they have two arguments
    /// or more. Linear in the body.
    fn of(f: &Function) -> Option<TrigBlock> {
        let mut b = TrigBlock { members: Vec::new(), args: Vec::new(), slot_of: HashMap::new() };
        let mut slot: HashMap<usize, usize> = HashMap::new();
        for &v in &f.body {
            let Def::Trig(t, a) = f.value(v).def else { continue };
            if !matches!(f.value(a).def, Def::Input) {
                continue;
            }
            let k = *slot.entry(a.index()).or_insert_with(|| {
                b.args.push(a);
                b.args.len() - 1
            });
            b.slot_of.insert(v.index(), (k, t == TrigFn::Sin));
            b.members.push(v);
        }
        (b.args.len() >= 2).then_some(b)
    }

    /// The block's statement: the arguments into `robovec_ta` (padded with zeros to a multiple
    /// of [`super::trig::block_pad`]), one `robovec_sincos_n`, then each member's value.
    fn write(&self, body: &Body, s: &mut String) {
        let real = body.o.real();
        let pad = super::trig::block_pad(body.o.f32());
        let n = self.args.len().div_ceil(pad) * pad;
        let zero = literal::operand(0.0, body.o.f32());
        // An input in a format reads as the file's real type (a fixed-point integer scaled).
        let args: Vec<String> = self
            .args
            .iter()
            .map(|&a| body.read(&Operand::Value(a), false))
            .chain(std::iter::repeat_n(zero, n - self.args.len()))
            .collect();
        let _ = writeln!(
            s,
            "  const {real} robovec_ta[{n}] = {{{}}};\n  {real} robovec_ts[{n}], robovec_tc[{n}];\n  \
             robovec_sincos_n(robovec_ta, robovec_ts, robovec_tc, {n});",
            args.join(", ")
        );
        for &v in &self.members {
            let (k, sin) = self.slot_of[&v.index()];
            let slot = format!("robovec_t{}[{k}]", if sin { 's' } else { 'c' });
            let _ = writeln!(s, "  const {} {} = {};", body.type_of(v), body.names[v.index()], body.stored(v, slot));
        }
    }
}

/// `trig=inline`: for the first `sin` and the first `cos` of each coordinate that has both,
/// value index → (the other one, true for the one that comes first in the body: its statement
/// computes both with one reduction, the other's is empty, [`Body::order`] attaches it).
fn fused_trig(f: &Function) -> HashMap<usize, (Value, bool)> {
    // The first sin and the first cos of each coordinate, in body order: when the second of
    // the two appears, its partner is already here and comes first.
    let mut first: HashMap<(usize, bool), Value> = HashMap::new();
    let mut out = HashMap::new();
    for &v in &f.body {
        let Def::Trig(t, a) = f.value(v).def else { continue };
        let is_sin = t == TrigFn::Sin;
        if first.contains_key(&(a.index(), is_sin)) {
            continue;
        }
        first.insert((a.index(), is_sin), v);
        if let Some(&lead) = first.get(&(a.index(), !is_sin)) {
            out.insert(lead.index(), (v, true));
            out.insert(v.index(), (lead, false));
        }
    }
    out
}
