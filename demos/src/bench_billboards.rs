//! The `bench billboards` sweep (in progress).
