//! The starter (`src/starter.rs`, the file to copy) on QEMU's `mps2-an386` board, as CI runs it
//! (`.ci/firmware.sh`, step "starter firmware"). This wrapper only adds what is particular to
//! this crate: the board's vector table (`src/vectors.rs`; this crate turns on cortex-m-rt's
//! `device` feature). The program itself, its entry point and its panic handler are all in
//! `src/starter.rs`, unchanged from what a fresh `cortex-m-rt` crate builds as its `src/main.rs`.
#![no_std]
#![no_main]

#[path = "../vectors.rs"]
mod vectors;

// The starter's own `#![no_std]` and `#![no_main]` are for the crate root it becomes in a copy;
// here, in a module, they are redundant (the two lines above say the same).
#[allow(unused_attributes)]
#[path = "../starter.rs"]
mod starter;
