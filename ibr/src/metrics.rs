//! Image error metrics (in progress).
