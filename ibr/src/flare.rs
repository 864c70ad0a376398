//! Lens flare (in progress).
