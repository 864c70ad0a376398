//! Shared code of the Parallax binaries (argument parsing helpers, scene building, output).
