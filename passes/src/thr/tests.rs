//! Unit tests of the cluster rewrites.
