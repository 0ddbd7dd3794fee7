//! The instruction set the packet kernels run on, chosen at run time: the crate's only
//! `unsafe` code.
//!
//! The kernels of [`crate::render::bvh_packet`] are safe, generic loops over `[f32; N]`. This
//! module compiles them three times — for AVX-512 (16 lanes: one packet in one traversal),
//! AVX2 (8 lanes: two half packets) and the target's baseline (4 lanes: SSE2 on x86-64, or
//! any other architecture) — with `#[target_feature]`, and calls the best one the CPU has.
//! Calling a `#[target_feature]` function is `unsafe` because running it on a CPU without
//! those instructions is undefined behaviour; each call below is made only for an [`Isa`]
//! that [`Isa::available`] confirmed with `is_x86_feature_detected!`, which every caller goes
//! through ([`Isa::check`]). Nothing else here is unsafe: no pointers, no unchecked indexing.
//!
//! Every ISA gives every ray the same hit, bit for bit, as the per-ray traversal (its
//! brute-force twin): `tests/accel.rs` runs each available ISA against it.
#![allow(unsafe_code)]

use std::sync::OnceLock;

use crate::render::bvh::Bvh;
use crate::render::bvh_packet::{self, PacketStack, RayPacket};
use crate::render::instances::InstanceLevel;

/// An instruction set the packet kernels are compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// AVX-512 (F, VL, BW, DQ): 16 lanes.
    Avx512,
    /// AVX2: 8 lanes.
    Avx2,
    /// The target's baseline (SSE2 on x86-64): 4 lanes.
    Portable,
}

/// The kernels every packet query uses unless it names others: [`Isa::best`].
static BEST: OnceLock<Isa> = OnceLock::new();

impl Isa {
    pub const ALL: [Isa; 3] = [Isa::Avx512, Isa::Avx2, Isa::Portable];

    /// Whether this CPU runs the kernels of `self`.
    pub fn available(self) -> bool {
        match self {
            Isa::Portable => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => {
                std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx512vl")
                    && std::arch::is_x86_feature_detected!("avx512bw")
                    && std::arch::is_x86_feature_detected!("avx512dq")
                    && std::arch::is_x86_feature_detected!("avx2")
            }
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => std::arch::is_x86_feature_detected!("avx2"),
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// The widest available ISA (detected once), or the one [`Isa::limit_to`] set.
    pub fn best() -> Isa {
        *BEST.get_or_init(|| {
            Isa::ALL
                .into_iter()
                .find(|isa| isa.available())
                .unwrap_or(Isa::Portable)
        })
    }

    /// Makes `self` what [`Isa::best`] answers for the rest of the process, so that the
    /// renders and `bench` use `self`'s kernels (to time AVX2's or the portable ones on a
    /// CPU that has wider). Called before anything asked for the best.
    ///
    /// # Errors
    /// Where this CPU lacks `self`, or the best was already chosen and is another ISA.
    pub fn limit_to(self) -> Result<(), String> {
        if !self.available() {
            let runs: Vec<&str> = Isa::ALL
                .into_iter()
                .filter(|isa| isa.available())
                .map(Isa::name)
                .collect();
            return Err(format!(
                "this CPU lacks {} (it runs {})",
                self.name(),
                runs.join(", ")
            ));
        }
        match *BEST.get_or_init(|| self) {
            chosen if chosen == self => Ok(()),
            chosen => Err(format!(
                "the kernels were already chosen ({}) before {} was asked for",
                chosen.name(),
                self.name()
            )),
        }
    }

    /// Rays per traversal.
    pub fn lanes(self) -> usize {
        match self {
            Isa::Avx512 => 16,
            Isa::Avx2 => 8,
            Isa::Portable => 4,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Isa::Avx512 => "avx512",
            Isa::Avx2 => "avx2",
            Isa::Portable => "portable",
        }
    }

    /// `self` where this CPU has it, else the portable kernels.
    #[inline]
    fn check(self) -> Isa {
        match self {
            Isa::Portable => Isa::Portable,
            _ if self == Isa::best() || self.available() => self,
            _ => Isa::Portable,
        }
    }
}

/// [`bvh_packet::closest`] on `isa`'s kernels (the portable ones where the CPU lacks `isa`).
#[inline]
pub fn closest(isa: Isa, bvh: &Bvh, packet: &mut RayPacket, stack: &mut PacketStack) {
    match isa.check() {
        // SAFETY: `check` returned the ISA only because this CPU has its features.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { x86::closest_avx512(bvh, packet, stack) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { x86::closest_avx2(bvh, packet, stack) },
        _ => bvh_packet::closest::<4>(bvh, packet, stack),
    }
}

/// [`bvh_packet::any`] on `isa`'s kernels (the portable ones where the CPU lacks `isa`).
#[inline]
pub fn any(isa: Isa, bvh: &Bvh, packet: &RayPacket, stack: &mut PacketStack) -> u32 {
    match isa.check() {
        // SAFETY: `check` returned the ISA only because this CPU has its features.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { x86::any_avx512(bvh, packet, stack) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { x86::any_avx2(bvh, packet, stack) },
        _ => bvh_packet::any::<4>(bvh, packet, stack),
    }
}

/// [`InstanceLevel::closest_packet`] on `isa`'s kernels (the portable ones where the CPU
/// lacks `isa`).
#[inline]
pub fn closest_instances(
    isa: Isa,
    level: &InstanceLevel,
    packet: &mut RayPacket,
    stack: &mut PacketStack,
) {
    match isa.check() {
        // SAFETY: `check` returned the ISA only because this CPU has its features.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { x86::closest_instances_avx512(level, packet, stack) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { x86::closest_instances_avx2(level, packet, stack) },
        _ => level.closest_packet::<4>(packet, stack),
    }
}

/// [`InstanceLevel::any_packet`] on `isa`'s kernels (the portable ones where the CPU lacks
/// `isa`).
#[inline]
pub fn any_instances(
    isa: Isa,
    level: &InstanceLevel,
    packet: &RayPacket,
    stack: &mut PacketStack,
) -> u32 {
    match isa.check() {
        // SAFETY: `check` returned the ISA only because this CPU has its features.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => unsafe { x86::any_instances_avx512(level, packet, stack) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => unsafe { x86::any_instances_avx2(level, packet, stack) },
        _ => level.any_packet::<4>(packet, stack),
    }
}

/// The kernels compiled per ISA (no fused multiply-add: `fma` is not enabled, and Rust
/// never fuses a multiply and an add on its own, so every lane rounds as the per-ray path).
#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::*;

    #[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,avx,bmi1,bmi2,lzcnt,popcnt")]
    pub(super) fn closest_avx512(bvh: &Bvh, packet: &mut RayPacket, stack: &mut PacketStack) {
        bvh_packet::closest::<16>(bvh, packet, stack)
    }

    #[target_feature(enable = "avx2,avx,bmi1,bmi2,lzcnt,popcnt")]
    pub(super) fn closest_avx2(bvh: &Bvh, packet: &mut RayPacket, stack: &mut PacketStack) {
        bvh_packet::closest::<8>(bvh, packet, stack)
    }

    #[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,avx,bmi1,bmi2,lzcnt,popcnt")]
    pub(super) fn any_avx512(bvh: &Bvh, packet: &RayPacket, stack: &mut PacketStack) -> u32 {
        bvh_packet::any::<16>(bvh, packet, stack)
    }

    #[target_feature(enable = "avx2,avx,bmi1,bmi2,lzcnt,popcnt")]
    pub(super) fn any_avx2(bvh: &Bvh, packet: &RayPacket, stack: &mut PacketStack) -> u32 {
        bvh_packet::any::<8>(bvh, packet, stack)
    }

    #[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,avx,bmi1,bmi2,lzcnt,popcnt")]
    pub(super) fn closest_instances_avx512(
        level: &InstanceLevel,
        packet: &mut RayPacket,
        stack: &mut PacketStack,
    ) {
        level.closest_packet::<16>(packet, stack)
    }

    #[target_feature(enable = "avx2,avx,bmi1,bmi2,lzcnt,popcnt")]
    pub(super) fn closest_instances_avx2(
        level: &InstanceLevel,
        packet: &mut RayPacket,
        stack: &mut PacketStack,
    ) {
        level.closest_packet::<8>(packet, stack)
    }

    #[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,avx,bmi1,bmi2,lzcnt,popcnt")]
    pub(super) fn any_instances_avx512(
        level: &InstanceLevel,
        packet: &RayPacket,
        stack: &mut PacketStack,
    ) -> u32 {
        level.any_packet::<16>(packet, stack)
    }

    #[target_feature(enable = "avx2,avx,bmi1,bmi2,lzcnt,popcnt")]
    pub(super) fn any_instances_avx2(
        level: &InstanceLevel,
        packet: &RayPacket,
        stack: &mut PacketStack,
    ) -> u32 {
        level.any_packet::<8>(packet, stack)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Once chosen, the best stays: limiting it to itself is allowed, to any other ISA an
    /// error, and so is an ISA this CPU lacks.
    #[test]
    fn the_best_is_limited_once_and_only_to_an_isa_this_cpu_runs() {
        let best = Isa::best();
        assert_eq!(best.limit_to(), Ok(()));
        for isa in Isa::ALL.into_iter().filter(|&isa| isa != best) {
            let why = isa.limit_to().unwrap_err();
            let want = if isa.available() {
                format!("already chosen ({})", best.name())
            } else {
                format!("this CPU lacks {}", isa.name())
            };
            assert!(why.contains(&want), "{why}");
        }
        assert_eq!(Isa::best(), best);
    }
}
