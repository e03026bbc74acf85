//! Caustic placeholder replaced below.
