//! The scale benchmark's input (issue 28): `copies` independent copies of the corpus's WALK-MAN
//! `dirdyna` (Robotran Matlab, 55 joints, ~37k ops each; see `robovec_testkit::copies`), written
//! to standard output:
//! `cargo run --release --example walkman_copies -- 16 > walkman_x16.m`.
//! The corpus is read from `../shared` beside the repository (or `ROBOVEC_SHARED`).
fn main() {
    let copies: usize = std::env::args().nth(1).map(|s| s.parse().expect("copies: a number")).unwrap_or(16);
    let shared =
        std::env::var("ROBOVEC_SHARED").unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/../shared").into());
    let path = format!("{shared}/corpus/robotran/matlab/walkman__mbs_dirdyna_walkman_robotran.m");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    print!("{}", robovec_testkit::copies::matlab_copies(&text, copies, 55));
}
