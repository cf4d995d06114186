//! C identifiers for the values and functions of a generated C file (issue 29): Robotran's
//! names where they are valid and safe C (`AlF15`, `S4`, `FM37_3`), otherwise sanitised
//! (`q[4]` → `q_4`, `frc[2][11].1` → `frc_2_11_1`) and made unique; never a name the file's C
//! cannot hold.
//!
//! # Reserved names
//! A value (a local variable of the generated function) never takes a name that [`is_reserved`]:
//! - a keyword of C89 to C23 or of GNU C (`asm`, `typeof`: GCC's and Clang's default dialects);
//! - an identifier the standard reserves: a leading `_` (`_Atomic`, `__LINE__`, every
//!   intrinsic of `<immintrin.h>`) or a `__` anywhere;
//! - an object-like macro of the headers the file includes (`<math.h>`, `<string.h>`,
//!   `<immintrin.h>`, which pulls in `<stdlib.h>`) or predefined by GCC or Clang in their
//!   default dialects (`linux`, `unix`): by family (`M_…` constants, `FP_…`, `MATH_ERR…`,
//!   `HUGE_VAL…`, the `INT…`/`UINT…` limits and `…_MAX`/`…_MIN`/`…_C`, errno's `E…`, `FE_…`)
//!   and by name (`NAN`, `INFINITY`, `NULL`, `math_errhandling`, `errno`, …); a function-like
//!   macro expands only before `(`, which no value is;
//! - what the file itself calls or defines: libm's `sin`, `cos`, `sqrt`, `fma` (and their `f`
//!   forms), `memcpy`, the helpers `robovec_…`, the macros `ROBOVEC_…`, the ABI's parameters.
//!
//! A function's symbol (external linkage, declared in the header) must also avoid every name
//! of the C and POSIX libraries a program includes and links with ([`is_reserved_symbol`]:
//! libm's functions with their `f`/`l`/`f128`/`d64`… forms, `<string.h>`'s `str…`/`mem…`,
//! `<stdlib.h>`'s, `main`, and every identifier of the C standard library (C89–C23), of POSIX
//! and of glibc, by name or by the families the standards reserve: `names/library.rs`, issue 47:
//! `printf`, `time`, `read`, `signal`, `pthread_create`, `SIGINT`), the names the file derives
//! from symbols (`…_INPUTS`, `…_OUTPUTS`, `…_partK`), and a name whose derived names fall in
//! such a family (`sem`: `sem_INPUTS`, `sem_part1` are POSIX's `sem_…`). `name=` is checked
//! against it (bad usage, exit 2); a symbol derived from a function's name is renamed
//! (`@time` → `v_time`).
//!
//! # Renaming
//! A name that is no identifier is sanitised; one that is reserved or taken becomes
//! `v_NAME` (leading `_` dropped, `__` folded to `_`: `_Atomic` → `v_Atomic`), then
//! `v_NAME_2`, `v_NAME_3`, … until a candidate is neither reserved nor taken: the renaming never
//! produces a reserved name (`M_PI` becomes `v_M_PI`, not the macro `M_PI_2`). `tests/c_names.rs`
//! checks the rules against the system compiler's own headers (`cc -dM -E`).

mod library;

use robovec_ir::Function;
use std::collections::HashSet;

/// Keywords of C89–C23 and GNU C (GCC's and Clang's default dialects), and the names of the
/// types the generated files use.
const KEYWORDS: &[&str] = &[
    "auto",
    "break",
    "case",
    "char",
    "const",
    "continue",
    "default",
    "do",
    "double",
    "else",
    "enum",
    "extern",
    "float",
    "for",
    "goto",
    "if",
    "inline",
    "int",
    "long",
    "register",
    "restrict",
    "return",
    "short",
    "signed",
    "sizeof",
    "static",
    "struct",
    "switch",
    "typedef",
    "union",
    "unsigned",
    "void",
    "volatile",
    "while",
    // C23 (and C11's spellings without underscore, macros of <stdbool.h>, <stdalign.h>, …)
    "alignas",
    "alignof",
    "bool",
    "constexpr",
    "false",
    "nullptr",
    "static_assert",
    "thread_local",
    "true",
    "typeof",
    "typeof_unqual",
    "noreturn",
    // GNU C
    "asm",
    "fortran",
];

/// Object-like macros (and variables) of the included headers and of the compilers'
/// predefinitions that no family of [`is_reserved`] covers.
const MACROS: &[&str] = &[
    "NAN",
    "INFINITY",
    "NULL",
    "HUGE",
    "DOMAIN",
    "SING",
    "OVERFLOW",
    "UNDERFLOW",
    "TLOSS",
    "PLOSS",
    "X_TLOSS",
    "math_errhandling",
    "errno",
    "signgam",
    "linux",
    "unix",
    "i386",
    "i486",
    "i586",
    "i686",
    "sun",
    "sparc",
    "mips",
    "vax",
    "stdin",
    "stdout",
    "stderr",
    "assert",
    "offsetof",
    "alloca",
    "RAND_MAX",
    "MB_CUR_MAX",
    "EOF",
    "LITTLE_ENDIAN",
    "BIG_ENDIAN",
    "PDP_ENDIAN",
    "BYTE_ORDER",
    "FLOAT_WORD_ORDER",
    "NFDBITS",
    "WNOHANG",
    "WUNTRACED",
    "WSTOPPED",
    "WEXITED",
    "WCONTINUED",
    "WNOWAIT",
    "WCOREFLAG",
    "P_ALL",
    "P_PID",
    "P_PGID",
    "P_PIDFD",
    "CLOCKS_PER_SEC",
    "TIME_UTC",
];

/// Prefixes of macro families of the included headers and of the names the standard reserves
/// for them (C17 §7.31).
const MACRO_PREFIXES: &[&str] = &[
    "M_", "FP_", "MATH_", "HUGE_VAL", "FE_", "FLT_", "DBL_", "LDBL_", "FD_", "EXIT_", "INT8", "INT16", "INT32",
    "INT64", "INT_", "INTMAX", "INTPTR", "UINT", "PTRDIFF_", "SIZE_", "SIG_", "SIGN", "WCHAR_", "WINT_", "PRI", "SCN",
    "LC_", "ATOMIC_", "ROBOVEC_", "robovec_", "__",
];

/// Suffixes of macro families (`SIZE_MAX`, `INT8_C`, `FLT_EPSILON`) and of the types of
/// `<stdint.h>` and POSIX (`size_t`, `int8_t`).
const SUFFIXES: &[&str] = &["_MAX", "_MIN", "_C", "_WIDTH", "_EPSILON", "_t"];

/// Functions of libm (C99–C23 and glibc's GNU extensions), each also reserved with the `f` and
/// `l` suffixes.
const MATH_FUNCTIONS: &[&str] = &[
    "acos",
    "acosh",
    "asin",
    "asinh",
    "atan",
    "atan2",
    "atanh",
    "cbrt",
    "ceil",
    "copysign",
    "cos",
    "cosh",
    "erf",
    "erfc",
    "exp",
    "exp2",
    "expm1",
    "fabs",
    "fdim",
    "floor",
    "fma",
    "fmax",
    "fmin",
    "fmod",
    "frexp",
    "hypot",
    "ilogb",
    "ldexp",
    "lgamma",
    "llrint",
    "llround",
    "log",
    "log10",
    "log1p",
    "log2",
    "logb",
    "lrint",
    "lround",
    "modf",
    "nan",
    "nearbyint",
    "nextafter",
    "nexttoward",
    "pow",
    "remainder",
    "remquo",
    "rint",
    "round",
    "scalbln",
    "scalbn",
    "sin",
    "sinh",
    "sqrt",
    "tan",
    "tanh",
    "tgamma",
    "trunc",
    "acospi",
    "asinpi",
    "atanpi",
    "atan2pi",
    "cospi",
    "sinpi",
    "tanpi",
    "compoundn",
    "pown",
    "powr",
    "rootn",
    "rsqrt",
    "exp10",
    "exp10m1",
    "exp2m1",
    "log10p1",
    "log2p1",
    "logp1",
    "fmaximum",
    "fminimum",
    "fmaximum_num",
    "fminimum_num",
    "fmaximum_mag",
    "fminimum_mag",
    "fmaximum_mag_num",
    "fminimum_mag_num",
    "nextup",
    "nextdown",
    "canonicalize",
    "fromfp",
    "ufromfp",
    "fromfpx",
    "ufromfpx",
    "llogb",
    "roundeven",
    "fadd",
    "fsub",
    "fmul",
    "fdiv",
    "ffma",
    "fsqrt",
    "dadd",
    "dsub",
    "dmul",
    "ddiv",
    "dfma",
    "dsqrt",
    "j0",
    "j1",
    "jn",
    "y0",
    "y1",
    "yn",
    "gamma",
    "drem",
    "finite",
    "significand",
    "scalb",
    "pow10",
    "sincos",
    "lgamma_r",
    "gamma_r",
    "matherr",
    "fpclassify",
    "signbit",
    "isnan",
    "isinf",
    "isfinite",
    "isnormal",
    "iszero",
    "issignaling",
    "issubnormal",
    "iscanonical",
    "isgreater",
    "isgreaterequal",
    "isless",
    "islessequal",
    "islessgreater",
    "isunordered",
    "iseqsig",
    "totalorder",
    "totalordermag",
    "getpayload",
    "setpayload",
    "setpayloadsig",
];

/// Other functions of the C library (`<string.h>`, `<stdlib.h>`, which `<immintrin.h>` pulls
/// in, and their POSIX/GNU companions) that no family covers: a symbol may not take them.
const LIBC_FUNCTIONS: &[&str] = &[
    "main",
    "bcmp",
    "bcopy",
    "bzero",
    "index",
    "rindex",
    "ffs",
    "ffsl",
    "ffsll",
    "stpcpy",
    "stpncpy",
    "explicit_bzero",
    "abs",
    "labs",
    "llabs",
    "div",
    "ldiv",
    "lldiv",
    "atof",
    "atoi",
    "atol",
    "atoll",
    "rand",
    "srand",
    "malloc",
    "calloc",
    "realloc",
    "reallocarray",
    "free",
    "aligned_alloc",
    "posix_memalign",
    "valloc",
    "memalign",
    "abort",
    "exit",
    "atexit",
    "at_quick_exit",
    "quick_exit",
    "getenv",
    "secure_getenv",
    "system",
    "bsearch",
    "qsort",
    "mblen",
    "mbtowc",
    "wctomb",
    "mbstowcs",
    "wcstombs",
    "random",
    "srandom",
    "initstate",
    "setstate",
    "rand_r",
    "drand48",
    "erand48",
    "lrand48",
    "nrand48",
    "mrand48",
    "jrand48",
    "srand48",
    "seed48",
    "lcong48",
    "mkstemp",
    "mkostemp",
    "mkdtemp",
    "mktemp",
    "realpath",
    "setenv",
    "unsetenv",
    "putenv",
    "clearenv",
    "ecvt",
    "fcvt",
    "gcvt",
    "qecvt",
    "qfcvt",
    "qgcvt",
    "rpmatch",
    "getsubopt",
    "grantpt",
    "ptsname",
    "unlockpt",
    "posix_openpt",
    "getloadavg",
    "a64l",
    "l64a",
    "arc4random",
    "arc4random_buf",
    "arc4random_uniform",
    "on_exit",
    "select",
    "pselect",
    "major",
    "minor",
    "makedev",
    "free_sized",
    "free_aligned_sized",
    "memalignment",
    "mkstemps",
    "mkostemps",
];

fn is_keyword(name: &str) -> bool {
    KEYWORDS.contains(&name)
}

/// A function of libm, with its `f`/`l` forms and those of C23's other types (`f128`, `d64`, …:
/// [`library::MATH_SUFFIXES`]).
fn is_math_function(name: &str) -> bool {
    MATH_FUNCTIONS.contains(&name)
        || library::MATH_SUFFIXES.iter().filter_map(|s| name.strip_suffix(s)).any(|b| MATH_FUNCTIONS.contains(&b))
}

/// `p` followed by a lowercase letter: the standard's future names (`is…`, `to…`, `str…`,
/// `mem…`, `wcs…`, `atomic_…`).
fn lower_after(name: &str, p: &str) -> bool {
    name.strip_prefix(p).and_then(|r| r.chars().next()).is_some_and(|c| c.is_ascii_lowercase())
}

/// True when a value (a local variable of a generated function) may not be called `name`:
/// see the module doc ("Reserved names").
pub fn is_reserved(name: &str) -> bool {
    let upper_after = |p: &str| {
        name.strip_prefix(p)
            .and_then(|r| r.chars().next())
            .is_some_and(|c| c.is_ascii_uppercase() || c.is_ascii_digit())
    };
    is_keyword(name)
        || name.starts_with('_')
        || name.contains("__")
        || MACROS.contains(&name)
        || MACRO_PREFIXES.iter().any(|p| name.starts_with(p))
        || SUFFIXES.iter().any(|s| name.ends_with(s) && name.len() > s.len())
        // errno's macros: `E` then a digit or an uppercase letter (EDOM, ERANGE, E2BIG).
        || upper_after("E")
        // The functions the generated code calls.
        || ["sin", "cos", "sqrt", "fma", "sinf", "cosf", "sqrtf", "fmaf", "memcpy", "in", "out", "live", "lane"]
            .contains(&name)
}

/// True when a function of a generated file (external linkage) may not be called `name`:
/// [`is_reserved`], the functions of the C library and the names the file derives from
/// symbols (module doc).
pub fn is_reserved_symbol(name: &str) -> bool {
    reserved_symbol_reason(name).is_some()
}

/// Why `name` may not be a symbol of a generated file (`None`: it may), for the diagnostic of
/// `name=` (`"declared by <stdio.h> (the C standard library)"`).
pub fn reserved_symbol_reason(name: &str) -> Option<String> {
    let why = |s: &str| Some(s.to_string());
    if !is_c_identifier(name) {
        why("not a C identifier")
    } else if is_keyword(name) {
        why("a C keyword")
    } else if name.starts_with('_') || name.contains("__") {
        why("reserved by the C standard (a leading `_` or a `__`)")
    } else if name.starts_with("robovec_") || name.starts_with("ROBOVEC_") {
        why("reserved for robovec's own helpers and macros")
    } else if let Some(r) = library_name_reason(name) {
        Some(r)
    } else if is_reserved(name) {
        why("a macro or type of the C headers the file includes, or a name the generated code uses")
    } else if ["_INPUTS", "_OUTPUTS"].iter().any(|s| name.ends_with(s)) || part_suffix(name) {
        why("a name robovec derives from another symbol (`…_INPUTS`, `…_OUTPUTS`, `…_partK`)")
    } else if ["A", "a"].iter().any(|c| library::in_family(&format!("{name}_{c}"))) {
        Some(format!(
            "the start of a family of names the C or POSIX library reserves (`{name}_…`), which the names derived \
             from it (`{name}_INPUTS`, `{name}_part1`) would be in"
        ))
    } else {
        None
    }
}

/// Why `name` is a name of the C or POSIX library (libm's, the C library's of
/// [`LIBC_FUNCTIONS`], the standard's `str…`/`mem…`/`wcs…`/`is…`/`to…`/`atomic_…`, and
/// [`library`]'s), or a variant of one (`gmtime_r`, `fopen64`, `qsort_s`:
/// [`library::VARIANTS`]).
fn library_name_reason(name: &str) -> Option<String> {
    if is_math_function(name) || name.strip_suffix("_r").is_some_and(is_math_function) {
        Some("a function or macro of <math.h>".into())
    } else if [Some(name), name.strip_suffix("_r")].into_iter().flatten().any(|n| LIBC_FUNCTIONS.contains(&n))
        || ["str", "mem", "wcs", "is", "to", "atomic_"].iter().any(|p| lower_after(name, p))
    {
        Some("a function of the C library or a name the standard reserves for it".into())
    } else if let Some(r) = library::library_reason(name) {
        Some(r)
    } else {
        library::VARIANTS.iter().find_map(|s| {
            let base = name.strip_suffix(s).filter(|b| is_c_identifier(b))?;
            library_name_reason(base).map(|r| format!("a variant (`{s}`) of `{base}`, {r}"))
        })
    }
}

/// True for a name ending in `_part` and digits (the parts of a split function).
fn part_suffix(name: &str) -> bool {
    let t = name.trim_end_matches(|c: char| c.is_ascii_digit());
    t.len() < name.len() && (t.ends_with("_part") || t.contains("_part"))
}

/// `name` made a free identifier: itself when it is an identifier that `reserved` accepts and
/// is not in `taken`, else `v_NAME` (sanitised, leading `_` dropped, `__` folded), then
/// `v_NAME_2`, `v_NAME_3`, … (module doc, "Renaming").
pub fn free_name(name: &str, taken: &HashSet<String>, reserved: impl Fn(&str) -> bool) -> String {
    if is_c_identifier(name) && !reserved(name) && !taken.contains(name) {
        return name.to_string();
    }
    let mut base = sanitise(name).trim_start_matches('_').to_string();
    while base.contains("__") {
        base = base.replace("__", "_");
    }
    if base.is_empty() {
        base = "v".into();
    }
    if reserved(&base) {
        base = format!("v_{base}");
    }
    let ok = |n: &str| !reserved(n) && !taken.contains(n);
    if ok(&base) {
        return base;
    }
    (2..).map(|k| format!("{base}_{k}")).find(|n| ok(n)).expect("unbounded counter")
}

/// True when `s` is a C identifier (letters, digits, `_`, not starting with a digit).
pub fn is_c_identifier(s: &str) -> bool {
    let mut ch = s.chars();
    ch.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_') && ch.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// `q[4]` → `q_4`, `frc[2][11].1` → `frc_2_11_1`, `a-b` → `a_b`; a leading digit gets `v_`.
pub fn sanitise(name: &str) -> String {
    let mut s = String::with_capacity(name.len());
    for c in name.chars() {
        match c {
            ']' => {}
            c if c.is_ascii_alphanumeric() || c == '_' => s.push(c),
            _ => s.push('_'),
        }
    }
    while s.ends_with('_') && s.len() > 1 {
        s.pop();
    }
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert_str(0, "v_");
    }
    s
}

/// One C identifier per value of `f` (indexed by `Value::index()`), distinct from each other,
/// never [`is_reserved`], and distinct from `extra_reserved` (the ABI's parameter names, the
/// file's symbols and macros, callback names). Valid safe names are kept first, so a renamed
/// value never takes a Robotran name.
pub fn c_names(f: &Function, extra_reserved: &[&str]) -> Vec<String> {
    let mut taken: HashSet<String> = extra_reserved.iter().map(|s| s.to_string()).collect();
    let mut out: Vec<Option<String>> = vec![None; f.values.len()];
    for (i, d) in f.values.iter().enumerate() {
        if is_c_identifier(&d.name) && !is_reserved(&d.name) && !taken.contains(&d.name) {
            taken.insert(d.name.clone());
            out[i] = Some(d.name.clone());
        }
    }
    for (i, d) in f.values.iter().enumerate() {
        if out[i].is_none() {
            let name = free_name(&d.name, &taken, is_reserved);
            taken.insert(name.clone());
            out[i] = Some(name);
        }
    }
    out.into_iter().map(|n| n.expect("every value named")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::text::parse;

    #[test]
    fn robotran_names_stay_and_others_become_unique_identifiers() {
        let m = parse(
            "func @f { input %q[4] input %q_4 input %in input %double input %robovec_x \
             %AlF15 = %q[4] * %q_4  %frc[2][11].1 = %AlF15 + %in  %x = %double - %robovec_x \
             output c[1] = %frc[2][11].1 output c[2] = %x }",
        )
        .unwrap();
        let f = &m.functions[0];
        let n = c_names(f, &["in", "out"]);
        let by = |s: &str| n[f.lookup(s).unwrap().index()].clone();
        assert_eq!(by("AlF15"), "AlF15");
        assert_eq!(by("q_4"), "q_4", "a valid name keeps its name");
        assert_eq!(by("q[4]"), "q_4_2", "the sanitised name does not take it");
        assert_eq!(by("frc[2][11].1"), "frc_2_11_1");
        assert_eq!(by("in"), "v_in");
        assert_eq!(by("double"), "v_double");
        assert_eq!(by("robovec_x"), "v_robovec_x");
        let set: HashSet<&String> = n.iter().collect();
        assert_eq!(set.len(), n.len());
        assert!(n.iter().all(|s| is_c_identifier(s) && !is_reserved(s)));
    }

    /// The names: each reserved, and renamed to a name that is not (`M_PI` is not
    /// renamed to the macro `M_PI_2`); Robotran's own names are not reserved.
    #[test]
    fn reserved_names_are_renamed_to_unreserved_ones() {
        let hostile = [
            "_Atomic",
            "_Generic",
            "_Noreturn",
            "_Alignas",
            "_Static_assert",
            "_Thread_local",
            "__attribute__",
            "_Pragma",
            "__STDC__",
            "__LINE__",
            "FP_NAN",
            "FP_ZERO",
            "HUGE_VALL",
            "math_errhandling",
            "MATH_ERRNO",
            "M_PI_2",
            "M_SQRT2",
            "M_LN2",
            "asm",
            "typeof",
            "M_PI",
            "int",
            "sin",
            "memcpy",
            "fma",
            "restrict",
            "robovec_sincos_inline",
            "linux",
            "unix",
            "size_t",
            "INT8_MAX",
            "EDOM",
            "NAN",
            "errno",
            "bool",
        ];
        let taken: HashSet<String> = ["v_M_PI".to_string()].into_iter().collect();
        for h in hostile {
            assert!(is_reserved(h), "{h} is reserved");
            let n = free_name(h, &taken, is_reserved);
            assert!(is_c_identifier(&n) && !is_reserved(&n) && !taken.contains(&n), "{h} → {n}");
        }
        assert_eq!(free_name("M_PI", &taken, is_reserved), "v_M_PI_2", "taken, then a suffix");
        assert_eq!(free_name("size_t", &HashSet::new(), is_reserved), "v_size_t_2", "`v_size_t` ends in `_t`");
        assert_eq!(free_name("_Atomic", &HashSet::new(), is_reserved), "Atomic");
        for ok in ["AlF15", "S4", "C4", "FM37_3", "LDL29_1", "OB16_4", "ROcp1_25", "q", "s", "tsim", "OM13", "WM14_6"] {
            assert!(!is_reserved(ok), "{ok} is Robotran's and stays");
        }
    }

    /// Symbols: `name=` values the issue lists are refused with a reason; ordinary ones pass.
    #[test]
    fn reserved_symbols_have_a_reason() {
        for bad in [
            "int",
            "sin",
            "memcpy",
            "fma",
            "M_PI",
            "restrict",
            "_Atomic",
            "robovec_sincos_inline",
            "main",
            "strlen",
            "sinf",
            "free",
            "f_INPUTS",
            "f_part2",
            "1x",
            "a-b",
        ] {
            assert!(reserved_symbol_reason(bad).is_some(), "{bad}");
        }
        for ok in ["invdyna", "mbs_dirdyna", "model_invdyna", "arm", "f_1", "robot2"] {
            assert_eq!(reserved_symbol_reason(ok), None, "{ok}");
        }
    }

    /// Issue 47: the names of the C standard library (C89–C23, Annex K), of POSIX and of
    /// glibc, by list and by family, are no symbols; the ABIs' own names stay.
    #[test]
    fn library_names_are_reserved_symbols_and_robovecs_are_not() {
        let library = [
            // The issue's: <stdio.h>, <time.h>, <signal.h>, <setjmp.h>, <locale.h>, <stdlib.h>.
            "printf",
            "time",
            "clock",
            "signal",
            "fopen",
            "setlocale",
            "longjmp",
            "setjmp",
            "exit",
            "malloc",
            "raise",
            "fclose",
            "puts",
            "getchar",
            "remove",
            "rename",
            "tmpfile",
            "difftime",
            "mktime",
            "gmtime",
            "localeconv",
            "jmp_buf",
            "FILE",
            "BUFSIZ",
            "gets",
            // <fenv.h>, <threads.h>, <uchar.h>, <stdatomic.h>, <stdbit.h>, <stdckdint.h>, <wchar.h>, <complex.h>.
            "feclearexcept",
            "fegetround",
            "thrd_create",
            "mtx_lock",
            "cnd_wait",
            "tss_get",
            "call_once",
            "once_flag",
            "mbrtoc16",
            "c8rtomb",
            "atomic_load",
            "memory_order",
            "memory_order_relaxed",
            "kill_dependency",
            "stdc_count_ones",
            "ckd_add",
            "wprintf",
            "btowc",
            "wmemcpy",
            "cabs",
            "csqrtf",
            "cexp2l",
            "I",
            "complex",
            "and",
            "xor_eq",
            // C23 and Annex K, math with other types' suffixes, correctly rounded math.
            "timegm",
            "gmtime_r",
            "memset_explicit",
            "strfromd",
            "fopen_s",
            "printf_s",
            "abort_handler_s",
            "sinf128",
            "cosd64",
            "f32addf64",
            "dsqrtl",
            "cr_sin",
            "unreachable",
            // POSIX: <unistd.h>, <fcntl.h>, <signal.h>, <sys/select.h>, <poll.h>, <pthread.h>, ….
            "read",
            "write",
            "open",
            "close",
            "kill",
            "fork",
            "sleep",
            "pipe",
            "dup",
            "select",
            "poll",
            "link",
            "unlink",
            "access",
            "alarm",
            "chdir",
            "getpid",
            "sysconf",
            "sigaction",
            "sigemptyset",
            "nanosleep",
            "pthread_create",
            "sem_wait",
            "mq_open",
            "sched_yield",
            "clock_gettime",
            "timer_create",
            "mmap",
            "socket",
            "bind",
            "connect",
            "accept",
            "listen",
            "send",
            "recv",
            "getaddrinfo",
            "dlopen",
            "opendir",
            "stat",
            "chmod",
            "umask",
            "regcomp",
            "glob",
            "iconv",
            "tcsetattr",
            "wait",
            "waitpid",
            "environ",
            "optarg",
            "tzset",
            "daylight",
            "posix_spawn",
            "lio_listio",
            "getline",
            "fileno",
            "popen",
            // Macros and families: errno, signals, fcntl, stdint, locale, float, inttypes.
            "EINTR",
            "E2BIG",
            "SIGINT",
            "SIGKILL",
            "SIG_DFL",
            "O_RDONLY",
            "F_GETFL",
            "S_IRUSR",
            "SEEK_SET",
            "LC_ALL",
            "FE_UPWARD",
            "FLT_MAX",
            "DEC64_MANT_DIG",
            "PRId64",
            "SCNx32",
            "INT32_C",
            "UINT64_MAX",
            "TIME_UTC",
            "CLOCK_MONOTONIC",
            "PTHREAD_MUTEX_INITIALIZER",
            "WEXITSTATUS",
            "R_OK",
            "STDIN_FILENO",
            "CHAR_BIT",
            "L_tmpnam",
            "TMP_MAX_S",
            "B9600",
            "VMIN",
            "int32_t",
            "pid_t",
            "DIR",
            // glibc: its BSD/SVID/GNU extensions and libc.so.6's exports.
            "usleep",
            "daemon",
            "vfork",
            "sbrk",
            "asprintf",
            "pipe2",
            "dup3",
            "err",
            "warn",
            "ioctl",
            "flock",
            "backtrace",
            "gettext",
            "mount",
            "step",
            "fopen64",
            "readdir64_r",
            "isalpha_l",
            "fgets_unlocked",
            "qsort_s",
            "fd_set",
            "d_fileno",
            "no_argument",
            "TIOCSIG",
            // Reserved by the C standard for the implementation.
            "_Exit",
            "__x",
            "_start",
        ];
        for n in library {
            assert!(is_reserved_symbol(n), "{n} is the library's");
            let why = reserved_symbol_reason(n).unwrap();
            assert!(!why.is_empty(), "{n}");
            // Renamed to a name that is free.
            let r = free_name(n, &HashSet::new(), is_reserved_symbol);
            assert!(is_c_identifier(&r) && !is_reserved_symbol(&r), "{n} → {r}");
        }
        assert_eq!(free_name("time", &HashSet::new(), is_reserved_symbol), "v_time");
        assert_eq!(free_name("read", &HashSet::new(), is_reserved_symbol), "v_read");
        // The header the reason names.
        for (n, header) in [
            ("printf", "declared by <stdio.h> (the C standard library)"),
            ("time", "declared by <time.h> (the C standard library)"),
            ("longjmp", "declared by <setjmp.h> (the C standard library)"),
            ("read", "declared by <unistd.h> (POSIX)"),
            ("signal", "declared by <signal.h> (the C standard library)"),
            ("setlocale", "declared by <locale.h> (the C standard library)"),
            ("fopen64", "a variant (`64`) of `fopen`, declared by <stdio.h>"),
            ("qsort_s", "a variant (`_s`) of `qsort`, a function of the C library"),
            ("pthread_create", "reserved by POSIX for <pthread.h> (`pthread_…`)"),
            ("SIGINT", "reserved by the C standard for <signal.h> (`SIG…` then an uppercase letter or a digit)"),
            ("thrd_create", "reserved by the C standard for <threads.h> (`thrd_…` then a lowercase letter)"),
        ] {
            let why = reserved_symbol_reason(n).unwrap();
            assert!(why.starts_with(header), "{n}: {why}");
        }
        // A name whose derived names (`sem_INPUTS`, `sem_part1`) fall in a family.
        for n in ["sem", "pthread", "SIG", "O", "mq", "LC", "thrd", "atomic"] {
            assert!(is_reserved_symbol(n), "{n}: its derived names are the library's");
        }
        // The ABIs' names, the default prefix, Robotran's symbols, ordinary model names.
        for ok in [
            "rnea",
            "model_rnea",
            "model_crba",
            "model_nle",
            "model_aba",
            "dirdyna",
            "invdyna",
            "fordyna",
            "mbs_dirdyna",
            "mbs_invdyna",
            "mbs_cons_hJ",
            "mbs_cons_jdqd",
            "mbs_link",
            "mbs_link3D",
            "mbs_extforces",
            "mbs_sensor",
            "mbs_gensensor",
            "cons_hJ",
            "cons_jdqd",
            "link3D",
            "extforces",
            "sensor_3",
            "gensensor_2",
            "f",
            "f_1",
            "g",
            "AB",
            "ab",
            "arm",
            "ur5",
            "robot2",
            "sigma",
            "crba",
            "nle",
            "aba",
            "model",
            "v_time",
            "v_read",
            "v_link",
            "robot_model",
            "coman",
            "walkman",
            "E",
            "Sigma",
            "f32",
            "fd",
        ] {
            assert_eq!(reserved_symbol_reason(ok), None, "{ok}");
        }
    }
}
