//! Fuzz target: ibr::images::transforms::fuzz (a transforms.json capture and its files).
#![no_main]

libfuzzer_sys::fuzz_target!(init: engine::load::fuzz::init(), |data: &[u8]| ibr::images::transforms::fuzz(data));
