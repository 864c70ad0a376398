//! Fuzz target: engine::load::fuzz::gltf (see that module for the input's shape).
#![no_main]

libfuzzer_sys::fuzz_target!(init: engine::load::fuzz::init(), |data: &[u8]| engine::load::fuzz::gltf(data));
