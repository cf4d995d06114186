//! Runs the lalrpop processor on `src/**/*.lalrpop` (lalrpop book, "Quick start"); the
//! generated parsers land in `OUT_DIR` under the same relative path.
fn main() {
    lalrpop::Configuration::new()
        .use_cargo_dir_conventions()
        .emit_rerun_directives(true)
        .process()
        .expect("lalrpop grammar failed to build");
}
