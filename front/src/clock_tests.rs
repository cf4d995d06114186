//! The time limit stops every loop of a load (issue 28 item 3): with a clock that stops at
//! its k-th tick, for every k up to the ticks a whole load takes, the load ends with exactly
//! the time-out error: never a panic, a partial module, a diagnostic of a half-read file or a
//! second run through the C batch path. Past the last tick, the module is the one an unlimited
//! load gives.

use super::clock::Clock;
use super::synth::{straight_line_c, Shape};
use super::{parse_text, parse_with_clock, Language};

/// Loads `text` with a clock stopping at tick k, for k = 1, 2, … until a load completes;
/// checks each stop and returns the number of budgets that stopped.
fn every_stop(lang: Language, text: &str) -> u32 {
    let full = parse_text(lang, text, None).expect("the file loads");
    for k in 1.. {
        match parse_with_clock(lang, text, None, &Clock::after_ticks(k)) {
            Ok(m) => {
                assert_eq!(m, full, "{lang:?}: a completed load is the unlimited one");
                return k - 1;
            }
            Err(errs) => {
                assert_eq!(errs.len(), 1, "{lang:?} at tick {k}: {errs:?}");
                assert!(
                    errs[0].message.starts_with("time limit of 0 s reached while reading (line "),
                    "{lang:?} at tick {k}: {}",
                    errs[0].message
                );
            }
        }
    }
    unreachable!("a load ticks finitely often")
}

#[test]
fn every_loop_of_every_language_stops_with_the_time_out() {
    let c = straight_line_c(Shape { bytes: 3_000, joints: 3, temps_per_output: 2, ops_per_temp: 3 }).text;
    // The sensor file takes the C batch path (its `switch`).
    let sensor = "void sensor(MbsSensor *sens, MbsData *s, int isens)\n{\n  T1 = s->q[1]*2.0;\n  T2 = T1*T1;\n  \
                  switch (isens) {\n  case 1:\n    sens->P[1] = T2;\n    break;\n  case 2:\n    sens->P[1] = T1;\n    \
                  break;\n  }\n}\n";
    let matlab = "function [M,c] = dirdyna(s,tsim,usrfun)\nq = s.q;\n  C1 = cos(q(1));\n  T1 = s.dpt(1,2)*C1;\n  \
                  T2 = T1*T1+q(2);\n  M(1,1) = T2;\n  c(1) = T1-T2;\nend\n";
    let python = "import numpy as np\ndef dirdyna(M, c, s, tsim):\n  q = s.q\n  C1 = np.cos(q[1])\n  \
                  T1 = s.dpt[1,2]*C1\n  T2 = T1*T1+q[2]\n  M[1,1] = T2\n  c[1] = T1-T2\n";
    for (lang, text) in
        [(Language::C, c.as_str()), (Language::C, sensor), (Language::Matlab, matlab), (Language::Python, python)]
    {
        let stops = every_stop(lang, text);
        // Every token is lexed and every line or statement scanned and lowered with a tick:
        // at least one stop per line.
        let statements = text.matches(['\n']).count() as u32;
        assert!(stops > statements, "{lang:?}: {stops} stops for {statements} lines");
    }
}
