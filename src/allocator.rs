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
//! Large inputs (4 MiB and more, [`configure_for_input`]) get a purge delay of 100 ms instead:
//! at that size a pass frees and allocates again hundreds of megabytes, and returning them at
//! once makes the kernel fault and zero the pages again (WALK-MAN × 64 `sim`: 1.96 million page
//! faults, a third of its time in the kernel). Measured (this 2-core machine, alternating runs):
//! WALK-MAN × 16 pipeline 4.55 s → 4.27 s (peak 421 → 435 MB), × 64 23.5 s → 22.0 s (1 623 →
//! 1 645 MB); `atomise,asap-alap` on straight-line C of 10 MB 124 → 156 MB, 50 MB 575 → 590 MB
//! (12× the input: within the 20×). Below 4 MiB the delay stays 0: a 1 MB file would peak at
//! 29× its size instead of 19×.
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

/// Inputs from this size on get [`LARGE_INPUT_PURGE_DELAY_MS`] (module doc).
pub const LARGE_INPUT_BYTES: u64 = 4 << 20;

/// The purge delay of large inputs, ms.
pub const LARGE_INPUT_PURGE_DELAY_MS: i64 = 100;

/// The purge delay for an input of `bytes` bytes, ms: 0 below [`LARGE_INPUT_BYTES`], else
/// [`LARGE_INPUT_PURGE_DELAY_MS`].
pub fn purge_delay_for(bytes: u64) -> i64 {
    if bytes >= LARGE_INPUT_BYTES {
        LARGE_INPUT_PURGE_DELAY_MS
    } else {
        0
    }
}

/// Sets the purge delay for an input of `bytes` bytes ([`purge_delay_for`]); call it once the
/// input's size is known (after [`configure`]).
pub fn configure_for_input(bytes: u64) {
    // SAFETY: as in `configure`.
    unsafe { libmimalloc_sys::mi_option_set(PURGE_DELAY, purge_delay_for(bytes) as std::os::raw::c_long) }
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
        configure_for_input(LARGE_INPUT_BYTES);
        assert_eq!(unsafe { libmimalloc_sys::mi_option_get(PURGE_DELAY) }, 100);
        configure_for_input(LARGE_INPUT_BYTES - 1);
        assert_eq!(unsafe { libmimalloc_sys::mi_option_get(PURGE_DELAY) }, 0);
    }
}
