//! Random numbers: xoshiro256** seeded through splitmix64 (small, fast, the same everywhere).

/// The generator.
pub struct Rng([u64; 4]);

pub fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Rng {
    pub fn new(mut seed: u64) -> Self {
        Rng([(); 4].map(|_| splitmix64(&mut seed)))
    }

    pub fn next(&mut self) -> u64 {
        let s = &mut self.0;
        let result = s[1].wrapping_mul(5).rotate_left(7).wrapping_mul(9);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// Uniform in 0..n (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    /// Uniform in lo..=hi.
    pub fn range(&mut self, lo: usize, hi: usize) -> usize {
        lo + self.below(hi - lo + 1)
    }

    pub fn chance(&mut self, p: f64) -> bool {
        self.uniform(0.0, 1.0) < p
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next() >> 11) as f64 / (1u64 << 53) as f64)
    }

    /// Log-uniform in [lo, hi), 0 < lo < hi.
    pub fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.uniform(lo.ln(), hi.ln()).exp()
    }

    /// An element of a non-empty slice.
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }

    /// An element, or `None` for an empty slice.
    pub fn choose<'a, T>(&mut self, items: &'a [T]) -> Option<&'a T> {
        (!items.is_empty()).then(|| self.pick(items))
    }
}

/// The seed of sequence `k` of a model through FMI version `fmi` (2 or 3) in a run with the given
/// master seed. Its top bit is the version (set: FMI 3.0), so that a seed alone replays.
pub fn sequence_seed(master: u64, identifier: &str, fmi: u8, k: u64) -> u64 {
    let name =
        identifier.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3));
    let version = if fmi == 3 { 0x9e37_79b9_7f4a_7c15 } else { 0 };
    let mut state = master ^ name.rotate_left(17) ^ k.wrapping_mul(0xd6e8_feb8_6659_fd93) ^ version;
    let seed = splitmix64(&mut state) & !FMI3_BIT;
    if fmi == 3 {
        seed | FMI3_BIT
    } else {
        seed
    }
}

/// The bit of a sequence seed that marks an FMI 3.0 sequence.
const FMI3_BIT: u64 = 1 << 63;

/// The FMI version (2 or 3) of a sequence seed.
pub fn seed_version(seed: u64) -> u8 {
    if seed & FMI3_BIT != 0 {
        3
    } else {
        2
    }
}
