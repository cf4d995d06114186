//! The settings of the binaries' allocator (mimalloc, issue 28).
//!
//! `robovec-opt` and `robovec-gen` allocate with mimalloc: the passes allocate and free millions
//! of small vectors and maps per run, and glibc's allocator slowed down as the heap grew
//! (WALK-MAN × 16 pipeline 8.75 s → 7.70 s). With its defaults, mimalloc backs its arenas with
//! transparent huge pages (2 MB pages count whole in the resident memory) and returns freed
//! pages to the system only a second later, which raised the peak resident memory of small and
//! medium runs above the input's 20× (issue 28 item 4; `cargo bench --bench parse_scale`,
//! `atomise,asap-alap` on straight-line C):
//!
//! | input | glibc | mimalloc, defaults | no huge pages | no huge pages, [`configure`] |
//! |---|---|---|---|---|
//! | one line | 5 MB | 11 MB | 6 MB | 5 MB |
//! | 1 MB | 24 MB | 59 MB | 39 MB | 25 MB |
//! | 10 MB | 187 MB | 278 MB | 272 MB | 165 MB |
//! | 50 MB | 866 MB | 875 MB | 833 MB | 709 MB |
//!
//! Huge pages are off at build time (the `mimalloc` crate's `no_thp` feature, root
//! `Cargo.toml`); [`configure`] sets the purge delay to 0 at run time. The cost: WALK-MAN × 16
//! through `atomise,zero-removal,balance,asap-alap,place<pe=32>,sim` took 7.6 s instead of
//! 7.2 s (peak 460 MB instead of 490 MB).
//!
//! The only unsafe code of the workspace (the lint is `deny` everywhere else): mimalloc's
//! options are set through its C API.
#![allow(unsafe_code)]

/// `mi_option_purge_delay` in mimalloc v3's `mi_option_e` (`mimalloc.h`; default 1000 ms in
/// v3's `options.c`).
const PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// Sets mimalloc's options for a robovec process: freed memory purged without delay. Call it
/// first thing in `main`. Harmless when mimalloc is not the global allocator.
pub fn configure() {
    // SAFETY: `mi_option_set` stores an integer in mimalloc's option table (no pointer is
    // passed); the index is that option's in the linked mimalloc (checked by the test).
    unsafe { libmimalloc_sys::mi_option_set(PURGE_DELAY, 0) }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The index names the option meant: before [`configure`] it reads the purge delay's
    /// default, 1000 (ms), which no other option of `mi_option_e` has.
    #[test]
    fn purge_delay_index_is_that_of_the_linked_mimalloc() {
        // SAFETY: reads of mimalloc's option table.
        assert_eq!(unsafe { libmimalloc_sys::mi_option_get(PURGE_DELAY) }, 1000);
        configure();
        assert_eq!(unsafe { libmimalloc_sys::mi_option_get(PURGE_DELAY) }, 0);
    }
}
