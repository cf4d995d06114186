//! Issue 29 item 1: generated C links anywhere. Hostile names as IR value names and as `name=`,
//! the system compiler's own header macros as value names, libc's functions as function names,
//! and two generated files (both headers in one translation unit) linked into one program;
//! compiled by `cc` in its default dialect and with `-std=c99`, with
//! `-Werror=implicit-function-declaration`, and run: outputs equal `-eval` bit for bit.
//!
//! Issue 47: the names of the C standard library and POSIX as `name=` (bad usage) and as
//! function names (renamed: a program calling `time(NULL)` links beside `@time`), every
//! identifier of the machine's C and POSIX headers as a function name; two models under one
//! name get two include guards, and two models' C files compile `#include`d into one
//! translation unit.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use crate::common::{corpus_dir, opt, stderr, tmp};

/// The names the issue measured breaking the C, and a few more of the same kinds.
const HOSTILE: &[&str] = &[
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
    "int",
    "sin",
    "cos",
    "memcpy",
    "fma",
    "M_PI",
    "restrict",
    "robovec_sincos_inline",
    "robovec_vec",
    "in",
    "out",
    "live",
    "AB_INPUTS",
    "linux",
    "unix",
    "NULL",
    "errno",
    "bool",
    "true",
    "size_t",
    "EDOM",
    "INFINITY",
    "main",
];

/// The dialects every file is compiled in: the compiler's default and C99.
const DIALECTS: [&[&str]; 2] = [&[], &["-std=c99"]];

/// A function whose inputs and temporaries carry `names` (`%NAME`), each temporary a distinct
/// combination of the two inputs `a`, `b` and the previous one, with `sin`/`cos` trig values,
/// and one output per temporary.
fn hostile_ir(names: &[&str]) -> String {
    let mut s = String::from("func @f {\n  input %a\n  input %b\n");
    for (i, n) in names.iter().enumerate().filter(|(i, _)| i % 7 == 3) {
        let _ = i;
        s += &format!("  input %{n}\n");
    }
    s += "  %ts = sin %a\n  %tc = cos %b\n";
    let mut prev = "ts".to_string();
    for (i, n) in names.iter().enumerate() {
        if i % 7 == 3 {
            s += &format!("  %{n}.t = mul %{n}, %tc\n");
            prev = format!("{n}.t");
            continue;
        }
        let op = ["add", "mul", "sub"][i % 3];
        s += &format!("  %{n} = {op} %{prev}, {}\n", if i % 2 == 0 { "%a" } else { "%b" });
        prev = n.to_string();
    }
    s += &format!("  output o = %{prev}\n");
    for (i, n) in names.iter().enumerate().filter(|(i, _)| i % 7 != 3) {
        s += &format!("  output o{i} = %{n}\n");
    }
    s + "}\n"
}

/// `cc ARGS` in `dir`; panics with the compiler's messages when it fails.
fn cc(dir: &Path, args: &[&str]) {
    let o = Command::new("cc")
        .current_dir(dir)
        .args(["-O0", "-ffp-contract=off", "-Werror=implicit-function-declaration"])
        .args(args)
        .output()
        .expect("a C compiler `cc` on PATH (scripts/test.sh installs gcc)");
    assert!(o.status.success(), "cc {args:?} in {}:\n{}", dir.display(), String::from_utf8_lossy(&o.stderr));
}

/// `-eval` of `ir` (file in `dir`) on `inputs` (`extra`: `-function=…`): output name → value.
fn eval(dir: &Path, ir: &Path, inputs: &BTreeMap<String, f64>, extra: &[&str]) -> BTreeMap<String, f64> {
    let json = dir.join("inputs.json");
    std::fs::write(&json, serde_json::to_string(inputs).unwrap()).unwrap();
    let eval = format!("-eval={}", json.display());
    let mut args = vec![ir.to_str().unwrap(), eval.as_str()];
    args.extend(extra);
    let o = opt(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    v["outputs"].as_object().unwrap().iter().map(|(k, x)| (k.clone(), x.as_f64().unwrap())).collect()
}

/// The inputs `codegen<c;abi=plain>` documents in the report, in argument order, and its outputs.
fn interface(report: &Path) -> (Vec<String>, Vec<String>) {
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(report).unwrap()).unwrap();
    let list = |k: &str| r["codegen"][k].as_array().unwrap().iter().map(|x| x.as_str().unwrap().to_string()).collect();
    (list("inputs"), list("outputs"))
}

/// Writes `ir` as C with `options`, compiles it in both dialects with a driver that includes
/// its header, runs it on the inputs and checks every output against `-eval`: bit for bit, or
/// (`trig=inline`, robovec's own sin/cos, within an ulp of libm's) to 1e-12 relative.
fn compiles_and_equals_eval(dir: &Path, ir_text: &str, options: &str, batch: usize) {
    let exact = !options.contains("trig=inline");
    let ir = dir.join("f.rvir");
    std::fs::write(&ir, ir_text).unwrap();
    let (c, report) = (dir.join("f.c"), dir.join("r.json"));
    let o = opt(&[
        ir.to_str().unwrap(),
        &format!("-passes=atomise,codegen<c;{options}>"),
        "-o",
        c.to_str().unwrap(),
        &format!("-report={}", report.display()),
    ]);
    assert!(o.status.success(), "{options}: {}", stderr(&o));
    let (ins, outs) = interface(&report);
    let inputs: BTreeMap<String, f64> =
        ins.iter().enumerate().map(|(i, n)| (n.clone(), 0.1 + 0.37 * i as f64 - 0.9 * (i % 3) as f64)).collect();
    let want = eval(dir, &ir, &inputs, &[]);
    let symbol = "f";
    let mut driver = format!(
        "#include <stdio.h>\n#include \"f.h\"\nint main(void) {{\n  static double in[{symbol}_INPUTS * {batch}], out[{symbol}_OUTPUTS * {batch}];\n"
    );
    for (i, n) in ins.iter().enumerate() {
        for l in 0..batch {
            driver += &format!("  in[{}] = {:?};\n", i * batch + l, inputs[n]);
        }
    }
    driver += &format!("  {symbol}(in, out);\n  for (int j = 0; j < {symbol}_OUTPUTS * {batch}; j++) printf(\"%.17g\\n\", out[j]);\n  return 0;\n}}\n");
    std::fs::write(dir.join("main.c"), driver).unwrap();
    for dialect in DIALECTS {
        let mut args: Vec<&str> = dialect.to_vec();
        args.extend(["-o", "run", "main.c", "f.c", "-lm"]);
        cc(dir, &args);
        let run = Command::new(dir.join("run")).output().unwrap();
        let got: Vec<f64> = String::from_utf8(run.stdout).unwrap().lines().map(|l| l.parse().unwrap()).collect();
        assert_eq!(got.len(), outs.len() * batch);
        for (j, n) in outs.iter().enumerate() {
            for l in 0..batch {
                let (x, w) = (got[j * batch + l], want[n]);
                let close = if exact { x.to_bits() == w.to_bits() } else { (x - w).abs() <= 1e-12 * w.abs().max(1.0) };
                assert!(close, "{options} {dialect:?}: output {n} lane {l}: C {x} vs -eval {w}");
            }
        }
    }
}

/// Every hostile name as an input and a temporary: the C compiles in both dialects and equals
/// `-eval` bit for bit, one state with libm's sin/cos and four with the inline ones.
#[test]
fn hostile_value_names_compile_and_equal_eval() {
    let dir = tmp("hostile_values");
    let ir = hostile_ir(HOSTILE);
    compiles_and_equals_eval(&dir, &ir, "abi=plain", 1);
    compiles_and_equals_eval(&dir, &ir, "abi=plain;batch=4", 4);
    compiles_and_equals_eval(&dir, &ir, "abi=plain;batch=4;trig=inline", 4);
    compiles_and_equals_eval(&dir, &ir, "abi=plain;chunk=5", 1);
}

/// Every hostile name as `name=`: bad usage (exit 2) naming why, or, when it is a fine symbol,
/// C that compiles and equals `-eval`. Every name of the list is reserved.
#[test]
fn hostile_symbols_are_refused_with_a_reason() {
    let dir = tmp("hostile_symbols");
    let ir = dir.join("f.rvir");
    std::fs::write(&ir, hostile_ir(&["x", "y"])).unwrap();
    for n in HOSTILE {
        let o = opt(&[ir.to_str().unwrap(), &format!("-passes=atomise,codegen<c;name={n}>"), "-o", "/dev/null"]);
        assert_eq!(o.status.code(), Some(2), "name={n}: {}", stderr(&o));
        assert!(stderr(&o).contains(&format!("`{n}` cannot name generated C: it is")), "{n}: {}", stderr(&o));
    }
    let o = opt(&[ir.to_str().unwrap(), "-passes=atomise,codegen<c;name=robot_model>", "-o", "/dev/null"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// The compiler's own headers decide (not this test's list): every macro that `<math.h>`,
/// `<string.h>`, `<stdlib.h>` and `<immintrin.h>` define or the compiler predefines in its
/// default dialect and in C99, with a name the standard does not reserve, as a value name; the
/// C compiles in both dialects, one state and batches (which include `<immintrin.h>`).
#[test]
fn the_system_headers_macros_are_never_value_names() {
    let dir = tmp("header_macros");
    let mut names: Vec<String> = Vec::new();
    for dialect in DIALECTS {
        let o = Command::new("cc")
            .args(dialect)
            .args(["-dM", "-E", "-x", "c", "-"])
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped())
            .spawn()
            .and_then(|mut c| {
                use std::io::Write;
                c.stdin.take().unwrap().write_all(
                    b"#include <math.h>\n#include <string.h>\n#include <stdlib.h>\n#include <immintrin.h>\n",
                )?;
                c.wait_with_output()
            })
            .expect("cc -dM -E");
        assert!(o.status.success());
        for line in String::from_utf8(o.stdout).unwrap().lines() {
            let Some(rest) = line.strip_prefix("#define ") else { continue };
            let name: String = rest.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
            if !name.starts_with('_') && !names.contains(&name) {
                names.push(name);
            }
        }
    }
    assert!(names.len() > 50, "the headers define macros: {names:?}");
    for n in ["M_PI", "FP_NAN", "HUGE_VALL", "NAN", "RAND_MAX"] {
        assert!(names.iter().any(|m| m == n), "{n} among {names:?}");
    }
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    let ir = hostile_ir(&refs);
    compiles_and_equals_eval(&dir, &ir, "abi=plain", 1);
    compiles_and_equals_eval(&dir, &ir, "abi=plain;batch=4", 4);
    compiles_and_equals_eval(&dir, &ir, "abi=plain;batch=4;trig=inline", 4);
}

/// Functions named like the C library's (every identifier that `<math.h>`, `<string.h>` and
/// `<stdlib.h>` declare as a function, read from the preprocessed headers) and two IR names that
/// sanitise alike (`@f[1]`, `@f_1`): the symbols are renamed, unique, and the file compiles
/// with those headers forced in (`-include`), where a clash would be a conflicting declaration.
#[test]
fn functions_named_like_the_c_library_get_free_symbols() {
    let dir = tmp("library_symbols");
    let o = Command::new("cc")
        .args(["-E", "-P", "-x", "c", "-"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .and_then(|mut c| {
            use std::io::Write;
            c.stdin.take().unwrap().write_all(b"#include <math.h>\n#include <string.h>\n#include <stdlib.h>\n")?;
            c.wait_with_output()
        })
        .expect("cc -E");
    let text = String::from_utf8(o.stdout).unwrap();
    // `IDENT (` after a type or `*`: a declared function (attributes and macros' calls are
    // identifiers followed by `((`, skipped).
    let mut funcs: Vec<String> = Vec::new();
    let bytes: Vec<char> = text.chars().collect();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i].is_ascii_alphabetic() && (i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == '_'))
        {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == '_') {
                i += 1;
            }
            let name: String = bytes[start..i].iter().collect();
            let mut j = i;
            while j < bytes.len() && bytes[j] == ' ' {
                j += 1;
            }
            let before: String = bytes[start.saturating_sub(2)..start].iter().collect();
            if j + 1 < bytes.len()
                && bytes[j] == '('
                && bytes[j + 1] != '('
                && (before.ends_with(' ') || before.ends_with('*'))
                && !funcs.contains(&name)
                && !["if", "sizeof", "return", "while", "for", "switch"].contains(&name.as_str())
            {
                funcs.push(name);
            }
        } else {
            i += 1;
        }
    }
    for f in ["sin", "memcpy", "malloc", "strlen", "qsort"] {
        assert!(funcs.iter().any(|g| g == f), "{f} among {} functions", funcs.len());
    }
    let mut ir = String::new();
    for name in funcs.iter().map(String::as_str).chain(["f[1]", "f_1"]) {
        ir += &format!("func @{name} {{\n  input %a\n  %x = mul %a, %a\n  output o = %x\n}}\n");
    }
    std::fs::write(dir.join("m.rvir"), ir).unwrap();
    let (m, c) = (dir.join("m.rvir").display().to_string(), dir.join("m.c").display().to_string());
    let o = opt(&[&m, "-passes=atomise,codegen<c>", "-o", &c]);
    assert!(o.status.success(), "{}", stderr(&o));
    let h = std::fs::read_to_string(dir.join("m.h")).unwrap();
    assert!(h.contains("void f_1(") && h.contains("void f_1_2("), "@f[1] and @f_1: two symbols");
    for dialect in DIALECTS {
        let mut args: Vec<&str> = dialect.to_vec();
        args.extend([
            "-include", "math.h", "-include", "string.h", "-include", "stdlib.h", "-include", "m.h", "-c", "m.c",
        ]);
        cc(&dir, &args);
    }
}

/// Two generated files in one program: one module with `@AB` (3 inputs) and `@ab` (1 input),
/// whose size macros stay distinct, written twice with `batch=4` (vector types and helpers in
/// each file): with the inline sin/cos, and with libm's under `name=other`. Both headers in
/// one translation unit, both objects linked; libm's file equals `-eval` bit for bit, the
/// inline one to 1e-12.
#[test]
fn two_generated_files_include_and_link_together() {
    let dir = tmp("two_files");
    let ir = "func @AB {\n  input %a\n  input %b\n  input %c\n  %s = sin %a\n  %x = mul %s, %b\n  %y = add %x, %c\n  output y = %y\n}\n\
              func @ab {\n  input %a\n  %k = cos %a\n  output k = %k\n}\n";
    std::fs::write(dir.join("m.rvir"), ir).unwrap();
    let p = |s: &str| dir.join(s).display().to_string();
    for (out, options) in [("one.c", "codegen<c;batch=4;trig=inline>"), ("two.c", "codegen<c;batch=4;name=other>")] {
        let o = opt(&[&p("m.rvir"), &format!("-passes=atomise,{options}"), "-o", &p(out)]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let h = std::fs::read_to_string(dir.join("one.h")).unwrap();
    assert!(h.contains("#define AB_INPUTS 3") && h.contains("#define ab_INPUTS 1"), "{h}");
    let driver = "#include <stdio.h>\n#include \"one.h\"\n#include \"two.h\"\n\
        int main(void) {\n\
          double in[AB_INPUTS * 4], y[AB_OUTPUTS * 4], k[ab_INPUTS * 4], k2[other_ab_OUTPUTS * 4], y2[other_AB_OUTPUTS * 4];\n\
          for (int i = 0; i < AB_INPUTS * 4; i++) in[i] = 0.25 + 0.5 * i;\n\
          AB(in, y); ab(in, k); other_AB(in, y2); other_ab(in, k2);\n\
          for (int l = 0; l < 4; l++) printf(\"%.17g %.17g %.17g %.17g\\n\", y[l], y2[l], k[l], k2[l]);\n\
          return (int)(sizeof in / sizeof in[0]) != 12 || (int)(sizeof k / sizeof k[0]) != 4;\n}\n";
    std::fs::write(dir.join("main.c"), driver).unwrap();
    for dialect in DIALECTS {
        let mut args: Vec<&str> = dialect.to_vec();
        args.extend(["-o", "run", "main.c", "one.c", "two.c", "-lm"]);
        cc(&dir, &args);
        let run = Command::new(dir.join("run")).output().unwrap();
        assert!(run.status.success(), "the size macros size the arrays");
        let text = String::from_utf8(run.stdout).unwrap();
        assert_eq!(text.lines().count(), 4, "{text}");
        for (l, line) in text.lines().enumerate() {
            let v: Vec<f64> = line.split(' ').map(|x| x.parse().unwrap()).collect();
            let at = |i: usize| 0.25 + 0.5 * (i * 4 + l) as f64;
            let inputs: BTreeMap<String, f64> =
                [("a".to_string(), at(0)), ("b".into(), at(1)), ("c".into(), at(2))].into();
            let y = eval(&dir, &dir.join("m.rvir"), &inputs, &["-function=AB"])["y"];
            let k = eval(&dir, &dir.join("m.rvir"), &inputs, &["-function=ab"])["k"];
            assert_eq!(v[1].to_bits(), y.to_bits(), "lane {l}: libm's file vs -eval: {line}");
            assert_eq!(v[3].to_bits(), k.to_bits(), "lane {l}: libm's file vs -eval: {line}");
            assert!((v[0] - y).abs() <= 1e-12 * y.abs().max(1.0), "lane {l}: inline {} vs {y}", v[0]);
            assert!((v[2] - k).abs() <= 1e-12, "lane {l}: inline {} vs {k}", v[2]);
        }
    }
}

/// The C standard library's and POSIX's headers (C89–C23, POSIX.1-2017), each included only
/// where the machine has it (`__has_include`), and the glibc ones whose names
/// `passes/src/codegen/names/library.rs` lists.
const LIBRARY_HEADERS: &[&str] = &[
    "assert.h",
    "complex.h",
    "ctype.h",
    "errno.h",
    "fenv.h",
    "float.h",
    "inttypes.h",
    "iso646.h",
    "limits.h",
    "locale.h",
    "math.h",
    "setjmp.h",
    "signal.h",
    "stdalign.h",
    "stdarg.h",
    "stdatomic.h",
    "stdbit.h",
    "stdbool.h",
    "stdckdint.h",
    "stddef.h",
    "stdint.h",
    "stdio.h",
    "stdlib.h",
    "stdnoreturn.h",
    "string.h",
    "tgmath.h",
    "threads.h",
    "time.h",
    "uchar.h",
    "wchar.h",
    "wctype.h",
    "aio.h",
    "arpa/inet.h",
    "cpio.h",
    "dirent.h",
    "dlfcn.h",
    "fcntl.h",
    "fmtmsg.h",
    "fnmatch.h",
    "ftw.h",
    "glob.h",
    "grp.h",
    "iconv.h",
    "langinfo.h",
    "libgen.h",
    "monetary.h",
    "mqueue.h",
    "ndbm.h",
    "net/if.h",
    "netdb.h",
    "netinet/in.h",
    "netinet/tcp.h",
    "nl_types.h",
    "poll.h",
    "pthread.h",
    "pwd.h",
    "regex.h",
    "sched.h",
    "search.h",
    "semaphore.h",
    "spawn.h",
    "strings.h",
    "sys/ipc.h",
    "sys/mman.h",
    "sys/msg.h",
    "sys/resource.h",
    "sys/select.h",
    "sys/sem.h",
    "sys/shm.h",
    "sys/socket.h",
    "sys/stat.h",
    "sys/statvfs.h",
    "sys/time.h",
    "sys/times.h",
    "sys/types.h",
    "sys/uio.h",
    "sys/un.h",
    "sys/utsname.h",
    "sys/wait.h",
    "syslog.h",
    "tar.h",
    "termios.h",
    "ulimit.h",
    "unistd.h",
    "utime.h",
    "utmpx.h",
    "wordexp.h",
    "alloca.h",
    "byteswap.h",
    "endian.h",
    "err.h",
    "error.h",
    "execinfo.h",
    "getopt.h",
    "libintl.h",
    "malloc.h",
    "sys/file.h",
    "sys/ioctl.h",
    "sys/random.h",
    "sys/sendfile.h",
    "sys/sysinfo.h",
    "sys/epoll.h",
    "sys/eventfd.h",
    "sys/inotify.h",
    "sys/timerfd.h",
    "sys/signalfd.h",
    "pty.h",
    "utmp.h",
    "mntent.h",
    "shadow.h",
    "ifaddrs.h",
];

/// The dialects the library's headers are read and the generated file compiled in: the
/// compiler's default (glibc's BSD and SVID extensions), strict C99 with POSIX and XSI, and GNU.
const LIBRARY_DIALECTS: [&[&str]; 3] = [&[], &["-std=c99", "-D_XOPEN_SOURCE=700"], &["-D_GNU_SOURCE"]];

/// `cc ARGS` on `stdin`, its stdout (panics when it fails).
fn cc_stdout(args: &[&str], stdin: &str) -> String {
    use std::io::Write;
    let o = Command::new("cc")
        .args(args)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .and_then(|mut c| {
            c.stdin.take().unwrap().write_all(stdin.as_bytes())?;
            c.wait_with_output()
        })
        .expect("cc");
    assert!(o.status.success(), "cc {args:?}: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

/// Issue 47: `name=` a function, macro or type of the C or POSIX library is bad usage (exit
/// 2) that names the header, in every ABI, and the output is not written.
#[test]
fn c_and_posix_library_names_as_name_are_bad_usage() {
    let dir = tmp("library_name_option");
    let ir = dir.join("f.rvir");
    std::fs::write(&ir, hostile_ir(&["x", "y"])).unwrap();
    let out = dir.join("out.c");
    std::fs::write(&out, "kept").unwrap();
    let named = [
        ("printf", "declared by <stdio.h>"),
        ("time", "declared by <time.h>"),
        ("clock", "declared by <time.h>"),
        ("signal", "declared by <signal.h>"),
        ("fopen", "declared by <stdio.h>"),
        ("setlocale", "declared by <locale.h>"),
        ("longjmp", "declared by <setjmp.h>"),
        ("read", "declared by <unistd.h>"),
        ("write", "declared by <unistd.h>"),
        ("kill", "declared by <signal.h>"),
        ("fork", "declared by <unistd.h>"),
        ("sleep", "declared by <unistd.h>"),
        ("pipe", "declared by <unistd.h>"),
        ("dup", "declared by <unistd.h>"),
        ("poll", "declared by <poll.h>"),
        ("thrd_create", "reserved by the C standard for <threads.h>"),
        ("pthread_create", "reserved by POSIX for <pthread.h>"),
        ("SIGINT", "reserved by the C standard for <signal.h>"),
        ("FILE", "declared by <stdio.h>"),
        ("exit", "a function of the C library"),
        ("malloc", "a function of the C library"),
        ("select", "a function of the C library"),
    ];
    for (n, why) in named {
        for abi in ["plain", "robotran", "pinocchio"] {
            let o = opt(&[
                ir.to_str().unwrap(),
                &format!("-passes=atomise,codegen<c;abi={abi};name={n}>"),
                "-o",
                out.to_str().unwrap(),
            ]);
            assert_eq!(o.status.code(), Some(2), "abi={abi};name={n}: {}", stderr(&o));
            let e = stderr(&o);
            assert!(e.contains(&format!("`{n}` cannot name generated C: it is {why}")), "name={n}: {e}");
        }
    }
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "kept", "the output is not touched");
    assert!(!dir.join("out.h").exists());
}

/// Issue 47: IR functions named like the C and POSIX libraries' functions (`@time`, `@printf`,
/// `@read`, `@signal`, `@link`, `@exit`) get free symbols (`v_time`, …); a program that
/// includes the libraries' headers and the generated one compiles in both dialects, calls
/// `time(NULL)` (the C library's: the current time) and the generated functions, whose
/// outputs equal `-eval` bit for bit.
#[test]
fn functions_named_like_libc_functions_link_beside_libc() {
    let dir = tmp("library_functions_link");
    let names = ["time", "printf", "read", "signal", "link", "exit", "sleep", "fopen"];
    let mut ir = String::new();
    for (k, n) in names.iter().enumerate() {
        ir += &format!(
            "func @{n} {{\n  input %a\n  input %b\n  %s = sin %a\n  %x = mul %s, %b\n  %y = add %x, {k}.5\n  output y = %y\n}}\n"
        );
    }
    std::fs::write(dir.join("m.rvir"), &ir).unwrap();
    let p = |s: &str| dir.join(s).display().to_string();
    let o = opt(&[&p("m.rvir"), "-passes=atomise,codegen<c>", "-o", &p("m.c")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let h = std::fs::read_to_string(dir.join("m.h")).unwrap();
    for n in names {
        assert!(h.contains(&format!("void v_{n}(const double *restrict in, double *restrict out);")), "{n}: {h}");
        assert!(!h.contains(&format!("void {n}(")), "{n} keeps the library's name: {h}");
    }
    let mut driver = String::from(
        "#include <stdio.h>\n#include <stdlib.h>\n#include <time.h>\n#include <signal.h>\n#include <unistd.h>\n\
         #include \"m.h\"\nint main(void)\n{\n  time_t t = time(NULL);\n  double in[2] = {0.75, -1.25}, out[1];\n  \
         printf(\"%lld\\n\", (long long)t);\n",
    );
    for n in names {
        driver += &format!("  v_{n}(in, out);\n  printf(\"%.17g\\n\", out[0]);\n");
    }
    driver += "  return 0;\n}\n";
    std::fs::write(dir.join("main.c"), driver).unwrap();
    let inputs: BTreeMap<String, f64> = [("a".to_string(), 0.75), ("b".into(), -1.25)].into();
    let want: Vec<f64> = names
        .iter()
        .map(|n| eval(&dir, &dir.join("m.rvir"), &inputs, &[format!("-function={n}").as_str()])["y"])
        .collect();
    for dialect in DIALECTS {
        let mut args: Vec<&str> = dialect.to_vec();
        args.extend(["-Wall", "-Werror", "-o", "run", "main.c", "m.c", "-lm"]);
        cc(&dir, &args);
        let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().as_secs() as i64;
        let run = Command::new(dir.join("run")).output().unwrap();
        assert!(run.status.success(), "{dialect:?}: {:?}", run.status);
        let text = String::from_utf8(run.stdout).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 1 + names.len(), "{text}");
        let t: i64 = lines[0].parse().unwrap();
        assert!((t - now).abs() <= 60, "{dialect:?}: time(NULL) = {t}, the clock says {now}");
        for (k, n) in names.iter().enumerate() {
            let got: f64 = lines[1 + k].parse().unwrap();
            assert_eq!(got.to_bits(), want[k].to_bits(), "{dialect:?}: v_{n} {got} vs -eval {}", want[k]);
        }
    }
}

/// Issue 47, the general rule checked against the machine's own C library: every identifier
/// that the C and POSIX headers of [`LIBRARY_HEADERS`] hold in the three dialects of
/// [`LIBRARY_DIALECTS`] (every token of the preprocessed headers: functions, variables,
/// types, enumeration constants, parameters and members; and every macro) is the name of a
/// function of one module. The generated file compiles after all those headers (`-include`)
/// in each dialect with `-Wall -Werror` (GCC's built-in functions too), and none of its
/// functions is a symbol `libc.so.6` or `libm.so.6` exports.
#[test]
fn no_name_of_the_system_c_library_becomes_a_symbol() {
    let dir = tmp("library_symbols_all");
    let mut includes = String::new();
    for h in LIBRARY_HEADERS {
        includes += &format!("#if __has_include(<{h}>)\n#include <{h}>\n#endif\n");
    }
    std::fs::write(dir.join("all.h"), &includes).unwrap();
    let mut names: std::collections::BTreeSet<String> = std::collections::BTreeSet::new();
    let mut macros: std::collections::BTreeSet<String> = std::collections::BTreeSet::new();
    for dialect in LIBRARY_DIALECTS {
        let mut args: Vec<&str> = dialect.to_vec();
        args.extend(["-E", "-P", "-x", "c", "-"]);
        let text = cc_stdout(&args, &includes);
        let mut word = String::new();
        for c in text.chars().chain([' ']) {
            if c.is_ascii_alphanumeric() || c == '_' {
                word.push(c);
            } else {
                if word.starts_with(|c: char| c.is_ascii_alphabetic()) {
                    names.insert(std::mem::take(&mut word));
                }
                word.clear();
            }
        }
        args.insert(0, "-dM");
        for line in cc_stdout(&args, &includes).lines() {
            let Some(rest) = line.strip_prefix("#define ") else { continue };
            let name: String = rest.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
            if name.starts_with(|c: char| c.is_ascii_alphabetic()) {
                names.insert(name.clone());
                macros.insert(name);
            }
        }
    }
    for n in ["printf", "time", "read", "pthread_create", "SIGINT", "EINTR", "FILE", "jmp_buf", "O_RDONLY"] {
        assert!(names.contains(n), "{n} among {} names", names.len());
    }
    let mut ir = String::new();
    for n in &names {
        ir += &format!("func @{n} {{\n  input %a\n  %x = mul %a, %a\n  output o = %x\n}}\n");
    }
    std::fs::write(dir.join("m.rvir"), ir).unwrap();
    let (m, c) = (dir.join("m.rvir").display().to_string(), dir.join("m.c").display().to_string());
    let o = opt(&[&m, "-passes=atomise,codegen<c>", "-o", &c]);
    assert!(o.status.success(), "{}", stderr(&o));
    // No macro of the headers names a function (`d_fileno` would be `d_ino` where <dirent.h> is
    // included, whether or not that compiles).
    let header = std::fs::read_to_string(dir.join("m.h")).unwrap();
    let symbols: Vec<&str> = header.lines().filter_map(|l| l.strip_prefix("void ")?.split('(').next()).collect();
    assert_eq!(symbols.len(), names.len(), "one function per name");
    let named_like_macros: Vec<&&str> = symbols.iter().filter(|s| macros.contains(**s)).collect();
    assert!(named_like_macros.is_empty(), "symbols named like the headers' macros: {named_like_macros:?}");
    for dialect in LIBRARY_DIALECTS {
        let mut args: Vec<&str> = dialect.to_vec();
        args.extend(["-Wall", "-Werror", "-include", "all.h", "-include", "m.h", "-c", "m.c", "-o", "m.o"]);
        cc(&dir, &args);
    }
    // The symbols the object defines, against those of the C library's shared objects.
    let defined = |args: &[&str]| -> Vec<String> {
        let o = Command::new("nm").args(args).output().expect("nm (binutils, with gcc)");
        assert!(o.status.success(), "nm {args:?}");
        String::from_utf8(o.stdout)
            .unwrap()
            .lines()
            .filter_map(|l| {
                let f: Vec<&str> = l.split_whitespace().collect();
                // Global symbols (uppercase) and indirect functions (`i`: glibc's `memcpy`), not
                // undefined ones (`U`) nor version nodes (`A`).
                let global = f.len() == 3 && (f[1] == "i" || f[1].chars().all(|c| c.is_ascii_uppercase()));
                (global && f[1] != "U" && f[1] != "A").then(|| f[2].split('@').next().unwrap().to_string())
            })
            .collect()
    };
    let ours = defined(&[dir.join("m.o").to_str().unwrap()]);
    assert!(ours.len() >= names.len(), "one symbol per function: {} for {}", ours.len(), names.len());
    let mut exported = std::collections::HashSet::new();
    for lib in ["libc.so.6", "libm.so.6"] {
        let path = cc_stdout(&[&format!("-print-file-name={lib}")], "").trim().to_string();
        if Path::new(&path).is_absolute() {
            exported.extend(defined(&["-D", "--defined-only", &path]));
        }
    }
    assert!(exported.contains("printf") && exported.contains("time"), "libc's exports: {}", exported.len());
    let clashes: Vec<&String> = ours.iter().filter(|s| exported.contains(*s)).collect();
    assert!(clashes.is_empty(), "generated symbols the C library exports: {clashes:?}");
}

/// `robovec-opt SOURCE EXTRA… -passes=atomise,codegen<c;OPTIONS> -o dir/NAME.c -report=…`:
/// the inputs and outputs of the generated function, in argument order.
fn generate(dir: &Path, source: &[&str], options: &str, name: &str) -> (Vec<String>, Vec<String>) {
    let (c, report) = (dir.join(format!("{name}.c")), dir.join(format!("{name}.json")));
    let mut args: Vec<String> = source.iter().map(|s| s.to_string()).collect();
    args.extend([
        format!("-passes=atomise,codegen<c;{options}>"),
        "-o".into(),
        c.display().to_string(),
        format!("-report={}", report.display()),
    ]);
    let o = opt(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{source:?} {options}: {}", stderr(&o));
    interface(&report)
}

/// The include guard of a generated header (its first `#ifndef`).
fn guard(header: &Path) -> String {
    let h = std::fs::read_to_string(header).unwrap();
    h.lines().find_map(|l| l.strip_prefix("#ifndef ")).expect("an include guard").to_string()
}

const PENDULUM: &str = "examples/double_pendulum/mbs_invdyna_double_pendulum.c";
const ARM_URDF: &str = "examples/three_link_arm/three_link_arm.urdf";

/// Issue 47 item 8: two models written under the same name (`invdyna`, the default) get two
/// include guards, each the same on every run; including both headers no longer skips the
/// second silently (the compiler sees its `invdyna_INPUTS`, another size).
#[test]
fn two_models_under_one_name_get_two_stable_include_guards() {
    let dir = tmp("guards");
    let again = dir.join("again");
    std::fs::create_dir_all(&again).unwrap();
    let arm = [ARM_URDF, "-function=invdyna"];
    generate(&dir, &[PENDULUM], "abi=plain", "a");
    generate(&again, &[PENDULUM], "abi=plain", "a");
    generate(&dir, &arm, "abi=plain", "b");
    let (ga, gb) = (guard(&dir.join("a.h")), guard(&dir.join("b.h")));
    assert!(ga.starts_with("ROBOVEC_invdyna_H_") && gb.starts_with("ROBOVEC_invdyna_H_"), "{ga} {gb}");
    assert_ne!(ga, gb, "two models, one name: two guards");
    assert_eq!(
        std::fs::read_to_string(dir.join("a.h")).unwrap(),
        std::fs::read_to_string(again.join("a.h")).unwrap(),
        "the same model: the same header, guard included"
    );
    let h = std::fs::read_to_string(dir.join("a.h")).unwrap();
    assert_eq!(h.matches(&ga).count(), 2, "#ifndef and #define: {h}");
    // The pinocchio ABI's default prefix likewise (`model_rnea`…).
    generate(&dir, &[ARM_URDF, "--fold-params", "-function=invdyna"], "abi=pinocchio", "p");
    let gp = guard(&dir.join("p.h"));
    assert!(gp.starts_with("ROBOVEC_model_rnea_H_") && gp.len() == "ROBOVEC_model_rnea_H_".len() + 16, "{gp}");
    // Both headers of one name in one translation unit: the second is read, its size macro
    // clashes with the first's and the compiler says so.
    std::fs::write(dir.join("both.c"), "#include \"a.h\"\n#include \"b.h\"\nint main(void) { return 0; }\n").unwrap();
    let o = Command::new("cc").current_dir(&dir).args(["-Werror", "-c", "both.c", "-o", "both.o"]).output().unwrap();
    assert!(!o.status.success(), "the second header was skipped");
    assert!(String::from_utf8_lossy(&o.stderr).contains("invdyna_INPUTS"), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Issue 47 item 8: the C files of two models with default names (the double pendulum's
/// `invdyna`, m454's `dirdyna`), both `#include`d with their headers into one translation unit
/// that calls both: compiles under GCC and Clang with `-std=c99 -Wall -Wextra -pedantic
/// -Werror` and in GCC's default dialect, with one state, and with four (vector helpers, split
/// into parts, and robovec's inline sin/cos: the helpers are shared); the program runs and its
/// outputs equal `-eval` (bit for bit with libm's sin/cos, to 1e-12 with the inline ones), as
/// do those of a program that links the two files. Files of other `batch=` in one unit stop
/// the compilation with an `#error` that says why.
#[test]
fn two_models_c_files_include_into_one_translation_unit() {
    let m454 = corpus_dir().join("c/m454__mbs_dirdyna_m454_project.c").display().to_string();
    let value = |i: usize, lane: usize| 0.1 + 0.37 * i as f64 - 0.9 * (i % 3) as f64 + 0.01 * lane as f64;
    for (k, (options, batch)) in
        [("abi=plain", 1), ("batch=4;chunk=60", 4), ("batch=4;trig=inline;chunk=60", 4)].into_iter().enumerate()
    {
        let dir = tmp(&format!("one_unit_{k}"));
        let exact = !options.contains("trig=inline");
        let models = [
            ("a", "invdyna", generate(&dir, &[PENDULUM], options, "a"), PENDULUM.to_string()),
            ("b", "dirdyna", generate(&dir, &[&m454], options, "b"), m454.clone()),
        ];
        let mut body = String::new();
        let mut want: Vec<f64> = Vec::new();
        for (file, symbol, (ins, outs), source) in &models {
            let _ = file;
            body +=
                &format!("  {{\n    static double in[{symbol}_INPUTS * {batch}], out[{symbol}_OUTPUTS * {batch}];\n");
            for (i, _) in ins.iter().enumerate() {
                for l in 0..batch {
                    body += &format!("    in[{}] = {:?};\n", i * batch + l, value(i, l));
                }
            }
            body += &format!("    {symbol}(in, out);\n    for (int j = 0; j < {symbol}_OUTPUTS * {batch}; j++) printf(\"%.17g\\n\", out[j]);\n  }}\n");
            let per_lane: Vec<BTreeMap<String, f64>> = (0..batch)
                .map(|l| {
                    let inputs: BTreeMap<String, f64> =
                        ins.iter().enumerate().map(|(i, n)| (n.clone(), value(i, l))).collect();
                    eval(&dir, Path::new(source), &inputs, &[])
                })
                .collect();
            for n in outs {
                for lane in &per_lane {
                    want.push(lane[n]);
                }
            }
        }
        let main = format!("int main(void)\n{{\n{body}  return 0;\n}}\n");
        std::fs::write(
            dir.join("one.c"),
            format!(
                "#include <stdio.h>\n#include \"a.h\"\n#include \"b.h\"\n#include \"a.c\"\n#include \"b.c\"\n{main}"
            ),
        )
        .unwrap();
        std::fs::write(dir.join("main.c"), format!("#include <stdio.h>\n#include \"a.h\"\n#include \"b.h\"\n{main}"))
            .unwrap();
        let strict = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"];
        let builds: [(&str, &[&str], &[&str]); 4] = [
            ("gcc", &strict, &["one.c"]),
            ("clang", &strict, &["one.c"]),
            ("gcc", &["-Wall", "-Wextra", "-Werror"], &["one.c"]),
            ("gcc", &strict, &["main.c", "a.c", "b.c"]),
        ];
        for (compiler, flags, files) in builds {
            let o = Command::new(compiler)
                .current_dir(&dir)
                .args(["-O0", "-ffp-contract=off"])
                .args(flags)
                .args(files)
                .args(["-o", "run", "-lm"])
                .output()
                .unwrap_or_else(|e| panic!("{compiler} ({e}): scripts/test.sh installs gcc and clang"));
            assert!(
                o.status.success(),
                "{options}, {compiler} {flags:?} {files:?}:\n{}",
                String::from_utf8_lossy(&o.stderr)
            );
            let run = Command::new(dir.join("run")).output().unwrap();
            assert!(run.status.success());
            let got: Vec<f64> = String::from_utf8(run.stdout).unwrap().lines().map(|l| l.parse().unwrap()).collect();
            assert_eq!(got.len(), want.len(), "{options}: outputs of both functions, every lane");
            for (j, (x, w)) in got.iter().zip(&want).enumerate() {
                let close = if exact { x.to_bits() == w.to_bits() } else { (x - w).abs() <= 1e-12 * w.abs().max(1.0) };
                assert!(close, "{options}, {compiler} {files:?}: output {j}: C {x} vs -eval {w}");
            }
        }
    }
    // Helpers of two batch widths cannot be one: the second file's guard says so.
    let dir = tmp("one_unit_mixed");
    generate(&dir, &[PENDULUM], "batch=4", "a");
    generate(&dir, &[&m454], "batch=8", "b");
    std::fs::write(dir.join("one.c"), "#include \"a.c\"\n#include \"b.c\"\n").unwrap();
    let o = Command::new("cc").current_dir(&dir).args(["-c", "one.c", "-o", "one.o"]).output().unwrap();
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("must share batch=, precision=, trig= and slp="), "{e}");
}
