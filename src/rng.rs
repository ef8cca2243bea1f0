//! splitmix64: a tiny, self-contained generator whose output is fixed forever, so a vector
//! file is byte-reproducible from its seed on every machine and every crate version.

#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> SplitMix64 {
        SplitMix64(seed)
    }

    /// A generator for one named stream (one stage), independent of the other stages' draws,
    /// so adding a stage or a corner case elsewhere never changes this stream.
    pub fn for_stream(seed: u64, name: &str) -> SplitMix64 {
        // FNV-1a of the name, mixed into the seed.
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in name.bytes() {
            h = (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
        let mut g = SplitMix64(seed ^ h);
        g.next_u64();
        g
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in 0..n (n >= 1), by the multiply-high method (no modulo bias worth naming).
    pub fn below(&mut self, n: u64) -> u64 {
        debug_assert!(n >= 1);
        ((self.next_u64() as u128 * n as u128) >> 64) as u64
    }

    /// Uniform in lo..=hi.
    pub fn range(&mut self, lo: u64, hi: u64) -> u64 {
        debug_assert!(lo <= hi);
        lo + self.below(hi - lo + 1)
    }

    /// True with probability num / den.
    pub fn chance(&mut self, num: u64, den: u64) -> bool {
        self.below(den) < num
    }

    /// A uniform `bits`-wide value.
    pub fn bits(&mut self, bits: u32) -> u64 {
        if bits == 0 {
            0
        } else {
            self.next_u64() >> (64 - bits)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_sequence() {
        // The reference splitmix64 output for seed 0 (Vigna's splitmix64.c).
        let mut g = SplitMix64::new(0);
        assert_eq!(g.next_u64(), 0xe220_a839_7b1d_cdaf);
        assert_eq!(g.next_u64(), 0x6e78_9e6a_a1b9_65f4);
    }

    #[test]
    fn ranges_stay_inside() {
        let mut g = SplitMix64::new(7);
        for _ in 0..10_000 {
            let v = g.range(3, 9);
            assert!((3..=9).contains(&v));
            assert!(g.bits(5) < 32);
        }
        assert_eq!(SplitMix64::new(0).below(1), 0);
    }
}
