//! Exact scheduler (in progress).
