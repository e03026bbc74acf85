//! Memory latency by pointer chasing: a random cyclic permutation of cache lines in a buffer
//! of each size, followed one load at a time (each load's address is the previous load's
//! value, so nothing overlaps). Shows how much data a core of this machine keeps close — what
//! decides how environment maps and textures are laid out (ARCHITECTURE.md, BENCHMARKS.md).
//!
//!     rustc -O bench/latency/chase.rs -o /tmp/chase && /tmp/chase
use std::time::Instant;

fn main() {
    const LINE: usize = 64 / std::mem::size_of::<usize>();
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut random = move |n: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % n as u64) as usize
    };
    let mut kb = 16;
    while kb <= 64 * 1024 {
        let lines = kb * 1024 / 64;
        let mut order: Vec<usize> = (0..lines).collect();
        for i in (1..lines).rev() {
            order.swap(i, random(i + 1));
        }
        let mut next = vec![0usize; lines * LINE];
        for i in 0..lines {
            next[order[i] * LINE] = order[(i + 1) % lines] * LINE;
        }
        let steps = 20_000_000;
        let (mut at, start) = (0, Instant::now());
        for _ in 0..steps {
            at = next[at];
        }
        let ns = start.elapsed().as_nanos() as f64 / steps as f64;
        println!("{kb:>6} KB: {ns:6.1} ns per dependent load (ended at {at})");
        kb *= 2;
    }
}
