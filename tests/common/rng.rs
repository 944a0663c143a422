//! The tests' one random source, shared by the integration tests (`common`)
//! and the loader's unit tests, which include this file by its path.

/// The tests' one random source: xorshift64, reproducible from its seed.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// A whole number in 0..n (0 when n is 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }

    /// A double in [0, 1).
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A unit vector, uniform on the sphere (by rejection from the cube).
    pub fn unit(&mut self) -> glam::DVec3 {
        loop {
            let v = glam::DVec3::new(
                self.f64() * 2.0 - 1.0,
                self.f64() * 2.0 - 1.0,
                self.f64() * 2.0 - 1.0,
            );
            let l = v.length();
            if l > 1e-3 && l <= 1.0 {
                return v / l;
            }
        }
    }
}
