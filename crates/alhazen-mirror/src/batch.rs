//! Batch placeholder replaced below.
