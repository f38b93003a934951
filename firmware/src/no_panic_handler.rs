//! The panic handler of every link-time no-panic binary (`nopanic`, `fp_*`): it calls a function
//! that exists nowhere, so the link fails (`undefined symbol:
//! __estimator_core_panic_path_reachable`) as soon as any panic path survives optimization. With
//! `--features locate-panics` it is a plain loop: the binary links, and the panic call sites can
//! be listed (`tools/panic_sites.py`).

#[cfg(not(feature = "locate-panics"))]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    extern "C" {
        /// Defined nowhere: referencing it makes the link fail if a panic is reachable.
        fn __estimator_core_panic_path_reachable() -> !;
    }
    // SAFETY: never executed when the binary links (the symbol does not exist).
    unsafe { __estimator_core_panic_path_reachable() }
}

#[cfg(feature = "locate-panics")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        core::hint::spin_loop();
    }
}
