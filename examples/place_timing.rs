//! Wall time of one placement of the synthetic DAG (`dag_gen::generate(n, 1)`) at N PEs:
//! `cargo run --release --example place_timing -- [n_ops] [N] [restarts]`.
use robovec_passes::place::{cycles, lower_bound, place_function, tight_lower_bound, PlaceOptions};

fn main() {
    let arg = |i: usize, d: u64| std::env::args().nth(i).map(|s| s.parse().expect("a number")).unwrap_or(d);
    let (n, pes, restarts) = (arg(1, 600_000) as usize, arg(2, 16) as u32, arg(3, 64) as u32);
    let f = robovec_testkit::dag_gen::generate(n, 1);
    let o = PlaceOptions { restarts, ..PlaceOptions::with_pes(pes) };
    let t = std::time::Instant::now();
    let p = place_function(&f, &o);
    let dt = t.elapsed();
    let c = cycles(&f, &p);
    println!(
        "{n} ops, N={pes}: {c} cycles in {dt:.2?} (SPEC LB {}, tight LB {})",
        lower_bound(&f, &o.arch),
        tight_lower_bound(&f, &o.arch)
    );
}
