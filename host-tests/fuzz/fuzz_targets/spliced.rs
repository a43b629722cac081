//! A realistic board stream with arbitrary bytes spliced in (and the bytes they replace cut
//! out): after the corruption ends, the parser must be back within a bound. The check itself is
//! `chassis_host_tests::splice::check_recovery`, shared with the regression tests.
#![no_main]

use chassis_host_tests::splice::{Splice, check_recovery};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|input: (u64, u16, u8, Vec<u8>)| {
    let (seed, at, cut, garbage) = input;
    let splice = Splice {
        seed,
        at,
        cut,
        garbage: &garbage,
    };
    if let Err(broken) = check_recovery(&splice) {
        panic!("{broken}");
    }
});
