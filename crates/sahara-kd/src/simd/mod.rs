//! Instruction-set levels, run-time CPU detection, and the one dispatch
//! from a query to the copy of its kernel compiled for the best level the
//! CPU has. Imports nothing else of the crate.
//!
//! The release binary targets baseline x86-64 (SSE2). Each query is written
//! once as a [`Kernel`], generic over a level `LEVEL`; [`dispatch`] runs it
//! inside a function compiled with that level's target features, so the
//! kernel (always inlined into it) is compiled once per level, and the
//! level constant selects the intrinsic forms of the leaf tests.

pub(crate) mod lanes;

/// The instruction-set levels a kernel is compiled for: each level has
/// the instructions of the ones below it.
pub(crate) mod level {
    /// Baseline: the lane loops, vectorised by the compiler.
    pub const PORTABLE: u8 = 0;
    /// AVX2 intrinsics in the leaf tests and packet walks.
    pub const AVX2: u8 = 1;
    /// AVX2 and AVX-512 (F + VL): the sixteen-ray walk, and the gathers
    /// from a compact block's vertex table (`vpermt2ps`).
    pub const AVX512: u8 = 2;
}

/// The widest instructions a structure's queries may use: each query runs
/// at the best level the CPU has, up to this one. Answers are the same bit
/// for bit at every level; only speed differs.
///
/// Why a caller would lower it: on Intel's server cores (measured on an
/// Ice Lake Xeon) 512-bit instructions lower the core's clock for about a
/// millisecond after the last one. A loop that runs mostly scalar code
/// (shading, sampling) with a walk now and then pays that lower clock on
/// all of its code; whole renders there measured 1.07-1.22x faster with
/// the queries held to AVX2. Queries in bulk (batches, sixteen-ray
/// packets, the protocol benchmark) keep AVX-512, where it pays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Isa {
    /// The portable code (baseline x86-64, vectorised by the compiler).
    Portable,
    /// AVX2 with FMA: vectors of 256 bits at most.
    Avx2,
    /// AVX-512 F and VL where the CPU has them (the default).
    #[default]
    Avx512,
}

impl Isa {
    /// The dispatch level this allows.
    #[inline(always)]
    pub(crate) const fn level(self) -> u8 {
        match self {
            Isa::Portable => level::PORTABLE,
            Isa::Avx2 => level::AVX2,
            Isa::Avx512 => level::AVX512,
        }
    }

    /// The limit of dispatch level `l`.
    pub(crate) const fn of_level(l: u8) -> Isa {
        match l {
            level::PORTABLE => Isa::Portable,
            level::AVX2 => Isa::Avx2,
            _ => Isa::Avx512,
        }
    }

    /// Its name: `portable`, `avx2` or `avx512`.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Portable => "portable",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }

    /// The limit named `s` (as [`Isa::name`] gives it).
    pub fn parse(s: &str) -> Option<Isa> {
        [Isa::Portable, Isa::Avx2, Isa::Avx512]
            .into_iter()
            .find(|i| i.name() == s)
    }
}

/// True when the CPU has AVX2, and the instructions every AVX2 CPU has
/// (FMA, POPCNT, BMI1, BMI2); std caches the CPUID query.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn has_avx2() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
        && std::arch::is_x86_feature_detected!("popcnt")
        && std::arch::is_x86_feature_detected!("bmi1")
        && std::arch::is_x86_feature_detected!("bmi2")
}

/// True when the CPU has AVX2 and AVX-512 F and VL.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn has_avx512() -> bool {
    has_avx2()
        && std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512vl")
}

/// The best level, up to `top`, that this CPU has.
#[inline(always)]
pub(crate) fn best_level(top: u8) -> u8 {
    #[cfg(target_arch = "x86_64")]
    {
        if top >= level::AVX512 && has_avx512() {
            return level::AVX512;
        }
        if top >= level::AVX2 && has_avx2() {
            return level::AVX2;
        }
    }
    let _ = top;
    level::PORTABLE
}

/// A query written once for every level.
pub(crate) trait Kernel {
    /// What the query returns.
    type Output;

    /// Run the query with level `LEVEL`'s instructions. Implementations
    /// are `#[inline(always)]`, so that they are compiled into the
    /// target-feature function [`dispatch`] calls them from.
    ///
    /// # Safety
    /// The CPU must have the level's instructions, and the caller must be
    /// compiled for them.
    unsafe fn run<const LEVEL: u8>(self) -> Self::Output;
}

/// Run `kernel` at the best level up to `top` that this CPU has.
#[inline(always)]
pub(crate) fn dispatch<K: Kernel>(top: u8, kernel: K) -> K::Output {
    match best_level(top) {
        // SAFETY (both): the CPU has the level's instructions (detected).
        #[cfg(target_arch = "x86_64")]
        level::AVX512 => unsafe { run_avx512(kernel) },
        #[cfg(target_arch = "x86_64")]
        level::AVX2 => unsafe { run_avx2(kernel) },
        // SAFETY: the portable level needs nothing.
        _ => unsafe { kernel.run::<{ level::PORTABLE }>() },
    }
}

/// `kernel` compiled for AVX2 (with FMA, POPCNT, BMI1, BMI2).
///
/// # Safety
/// The CPU must have them (`has_avx2`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,popcnt,bmi1,bmi2")]
unsafe fn run_avx2<K: Kernel>(kernel: K) -> K::Output {
    // SAFETY: AVX2 (the caller's contract), and this function is compiled
    // for it.
    unsafe { kernel.run::<{ level::AVX2 }>() }
}

/// `kernel` compiled for AVX2 and AVX-512 F, VL.
///
/// # Safety
/// The CPU must have AVX2 and AVX-512 F, VL.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,popcnt,bmi1,bmi2,avx512f,avx512vl")]
unsafe fn run_avx512<K: Kernel>(kernel: K) -> K::Output {
    // SAFETY: as `run_avx2`, for this level.
    unsafe { kernel.run::<{ level::AVX512 }>() }
}
