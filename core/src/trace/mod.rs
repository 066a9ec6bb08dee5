//! Scene queries, between the scene and the integrator: what a ray (or a
//! packet of rays, or a tile of camera packets) meets in a
//! [`Scene`](crate::scene::Scene).
//!
//! - [`scalar`]: one ray: [`closest_hit`], [`transmittance`] (shadow rays)
//!   and their `*_skip` forms, [`hit_point`].
//! - [`packet`]: [`Packet`]s of [`LANES`](crate::simd::LANES) rays: their
//!   twins [`closest_hits`] and [`transmittances`], bit for bit what the
//!   scalar queries give each lane.
//! - [`tile`]: camera packets ([`camera_hits`]) and tiles of them that share
//!   one walk of the BVH through their frustum ([`camera_tile_hits`]).
//!
//! The walks go through [`crate::accel`]'s BVH, which knows nothing of
//! scenes; the shapes' own tests, scalar and lane, are in
//! [`crate::geometry`].

pub mod packet;
pub mod scalar;
pub mod tile;

pub(crate) use packet::slab;
pub use packet::{Packet, PacketHits, closest_hits, closest_hits_portable, transmittances, transmittances_portable};
pub use scalar::{closest_hit, closest_hit_skip, hit_point, transmittance, transmittance_skip};
pub use tile::{CameraTile, TILE, camera_hits, camera_tile_hits};

/// No object (a lane's ray escapes, or the lane is unused).
pub const NO_OBJECT: u32 = u32::MAX;

/// Object `index` as a lane names it: [`NO_OBJECT`] for an index past
/// `u32` (a scalar path's "none", `usize::MAX`, becomes the lanes' none;
/// the packet walks name objects by `u32`).
#[inline(always)]
pub fn lane_object(index: usize) -> u32 {
    u32::try_from(index).unwrap_or(NO_OBJECT)
}
