//! Fuzz target: engine::load::fuzz::float_image (a depth map as PFM and as OpenEXR).
#![no_main]

libfuzzer_sys::fuzz_target!(init: engine::load::fuzz::init(), |data: &[u8]| engine::load::fuzz::float_image(data));
