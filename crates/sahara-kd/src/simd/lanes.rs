//! The eight-lane `f32` vectors of the leaf tests and packets, in array
//! form (loops the compiler vectorises) and in intrinsic form.

/// Lanes of a leaf block (triangles) or a packet (rays).
pub(crate) const WIDTH: usize = 8;

/// Eight `f32` lanes as an array.
pub(crate) type Lanes = [f32; WIDTH];

/// Eight `f32` lanes in a 256-bit register (AVX2 paths).
#[cfg(target_arch = "x86_64")]
pub(crate) type Lanes8 = std::arch::x86_64::__m256;
