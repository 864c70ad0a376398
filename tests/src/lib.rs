//! Test support shared by the integration tests: the golden-image helper and asset paths.
