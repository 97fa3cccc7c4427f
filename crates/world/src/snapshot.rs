//! Snapshot and restore: a copy of everything the next step depends on.
//!
//! | held in a [`Snapshot`]                        | why the next step needs it                     |
//! |-----------------------------------------------|------------------------------------------------|
//! | bodies (poses, velocities, masses, sleep timers, slots and generations) | the state itself, and which handles are live |
//! | shapes, broadphase trees and proxies, move buffer | pairs found next step, in the same order    |
//! | chains and their segment shapes               | chain handles resolve after a restore          |
//! | contacts with their warm-start impulses and feature ids, pair index | warm starting, begin/end events |
//! | joints, their accumulated impulses, the joint forest | warm starting, the direct solve          |
//! | islands, pending sleepers, sleep settings     | who sleeps when                                |
//! | portal pairs, crossings, clones, constraints  | crossings in progress                          |
//! | settings, gravity, step count, last events, counters | the same step, and the same reads       |
//!
//! The pre-solve hook (a closure the user owns) is not part of a snapshot:
//! [`World::restore`] keeps the hook the world has. A snapshot keeps the
//! world's owner id, so handles issued by the world it was taken from
//! resolve in the restored world (and in no other).

use crate::world::World;

/// A copy of a world's whole simulation state (see [`World::snapshot`]).
pub struct Snapshot {
    pub(crate) world: Box<World>,
}

impl Clone for Snapshot {
    fn clone(&self) -> Self {
        Snapshot {
            world: Box::new(self.world.copy_state()),
        }
    }
}

impl std::fmt::Debug for Snapshot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Snapshot")
            .field("bodies", &self.world.body_count())
            .field("step_count", &self.world.step_count())
            .finish()
    }
}

impl Snapshot {
    /// The state hash of the world the snapshot holds.
    #[must_use]
    pub fn state_hash(&self) -> u64 {
        self.world.state_hash()
    }

    /// A world continuing from the snapshot (no pre-solve hook).
    #[must_use]
    pub fn to_world(&self) -> World {
        self.world.copy_state()
    }
}

impl World {
    /// A copy of everything the next step depends on; continuing from
    /// [`restore`](Self::restore) gives bit-identical states.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 3.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// let saved = world.snapshot();
    /// for _ in 0..30 { world.step(1.0 / 60.0).unwrap(); }
    /// let after = world.state_hash();
    /// world.restore(&saved);
    /// for _ in 0..30 { world.step(1.0 / 60.0).unwrap(); }
    /// assert_eq!(world.state_hash(), after);
    /// ```
    #[must_use]
    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            world: Box::new(self.copy_state()),
        }
    }

    /// Puts the world back to `snapshot` (every stage, the step count and
    /// the last events); the callbacks (pre-solve hook, pair filter,
    /// friction and restitution callbacks) stay as they are: they are not
    /// state, and a snapshot holds none.
    pub fn restore(&mut self, snapshot: &Snapshot) {
        let hooks = std::mem::take(&mut self.hooks);
        *self = snapshot.world.copy_state();
        self.hooks = hooks;
    }
}

/// The bytes of a snapshot (with the `serde` feature): a versioned header,
/// then the world in [postcard](https://docs.rs/postcard)'s compact
/// encoding.
///
/// | bytes   | what                                                         |
/// |---------|--------------------------------------------------------------|
/// | 0..4    | magic `JNS2`                                                 |
/// | 4..6    | format version, little endian ([`SNAPSHOT_VERSION`](bytes::SNAPSHOT_VERSION)) |
/// | 6       | bytes per real: 4 (f32 build) or 8 (`f64` feature)           |
/// | 7       | 1 with the `portals` feature, else 0                         |
/// | 8..16   | payload length, little endian                                |
/// | 16..24  | FNV-1a 64 of the payload                                     |
/// | 24..    | payload: the world (postcard)                                |
///
/// Decoding checks every field of the header (bytes after the stated
/// payload length are refused) and the checksum before it decodes, then runs [`World::validate`] on the result: truncated,
/// corrupted or foreign bytes are a [`SnapshotError`](bytes::SnapshotError), never a panic.
#[cfg(feature = "serde")]
pub mod bytes {
    use super::Snapshot;
    use crate::world::World;

    /// The magic at the start of every snapshot.
    pub const SNAPSHOT_MAGIC: [u8; 4] = *b"JNS2";
    /// The format version this build writes and reads (2: contacts keep
    /// their recycling cache; 3: the contact set keeps each contact's
    /// island link; 4: body states carry flags instead of inverse masses,
    /// joints and portal constraints keep the masses they loaded; 6: the
    /// contact set keeps each contact's position in its bodies' lists, and
    /// the recycling cache no longer repeats the anchors; 7: a solved
    /// contact's colour lives only in the narrowphase's colour list; 8:
    /// joints are stored as `Joint` (one variant per kind) with their
    /// common solver data in `JointBase`, and the constraint graph and
    /// solved list belong to constraint building, not the narrowphase; 9:
    /// the portal stage keeps the events pushed between steps apart from
    /// the last step's; 12: events in one place — contacts keep their
    /// event switches, shapes their event fields, bodies their move-event
    /// switch, the portal stage no longer keeps the last step's events;
    /// 13: shape definitions carry an offset, bodies their motion locks
    /// and enabled flag, and the world its disabled joints; 14: the
    /// collision stage keeps the chains; 15: the solver settings' free-tree
    /// mass ratio, and the joint forest the policy it was built under;
    /// 16: a joint's base keeps its row count and threshold switch, a
    /// revolute joint its row switches and point-block bound; contacts and
    /// shapes list their hot fields first; 17: bodies keep their shapes'
    /// fast-travel limit and core reach, and the shape store the bodies
    /// whose extents changed since the last step; 18: every joint kind
    /// lists its solver base first; 19: a revolute joint no longer keeps
    /// its point block's bound, the islands keep no scratch, and the joint
    /// store keeps each joint's body slots).
    pub const SNAPSHOT_VERSION: u16 = 19;
    const HEADER: usize = 24;

    /// Why bytes are not a snapshot this build can restore.
    #[derive(Clone, Debug, PartialEq, Eq)]
    pub enum SnapshotError {
        /// Fewer bytes than the header, or than the payload length says.
        Truncated {
            /// Bytes needed.
            needed: usize,
            /// Bytes given.
            found: usize,
        },
        /// The bytes do not start with [`SNAPSHOT_MAGIC`].
        BadMagic,
        /// Written by another format version.
        WrongVersion {
            /// The version in the bytes.
            found: u16,
            /// [`SNAPSHOT_VERSION`].
            expected: u16,
        },
        /// Written by a build with another real type or feature set.
        WrongBuild {
            /// Bytes per real in the snapshot.
            real_bytes: u8,
            /// Portals feature in the snapshot.
            portals: bool,
        },
        /// More bytes than the header and the stated payload length.
        TrailingBytes {
            /// Bytes after the payload.
            extra: usize,
        },
        /// The payload's checksum does not match (corrupted bytes).
        Checksum,
        /// The payload does not decode (says where, in words).
        Decode(String),
        /// The payload decodes to a world that breaks an invariant.
        Invalid(crate::validate::InvariantError),
    }

    impl std::fmt::Display for SnapshotError {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            match self {
                SnapshotError::Truncated { needed, found } => {
                    write!(f, "snapshot truncated: {found} bytes, {needed} needed")
                }
                SnapshotError::BadMagic => write!(f, "not a janus2d snapshot"),
                SnapshotError::WrongVersion { found, expected } => {
                    write!(f, "snapshot version {found}, this build reads {expected}")
                }
                SnapshotError::WrongBuild {
                    real_bytes,
                    portals,
                } => write!(
                    f,
                    "snapshot of a build with {real_bytes}-byte reals, portals {portals}"
                ),
                SnapshotError::TrailingBytes { extra } => {
                    write!(f, "snapshot followed by {extra} bytes after its payload")
                }
                SnapshotError::Checksum => write!(f, "snapshot checksum mismatch"),
                SnapshotError::Decode(e) => write!(f, "snapshot does not decode: {e}"),
                SnapshotError::Invalid(e) => write!(f, "snapshot world invalid: {e}"),
            }
        }
    }

    impl std::error::Error for SnapshotError {}

    fn fnv(bytes: &[u8]) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in bytes {
            h ^= u64::from(*b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        h
    }

    fn build_bytes() -> (u8, u8) {
        (
            std::mem::size_of::<janus2d_core::math::Real>() as u8,
            u8::from(cfg!(feature = "portals")),
        )
    }

    impl Snapshot {
        /// The snapshot as bytes (header and postcard payload; see
        /// [`crate::snapshot::bytes`]).
        #[must_use]
        pub fn to_bytes(&self) -> Vec<u8> {
            let payload =
                postcard::to_allocvec(&*self.world).expect("every field of a world serializes");
            let (real, portals) = build_bytes();
            let mut out = Vec::with_capacity(HEADER + payload.len());
            out.extend_from_slice(&SNAPSHOT_MAGIC);
            out.extend_from_slice(&SNAPSHOT_VERSION.to_le_bytes());
            out.push(real);
            out.push(portals);
            out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
            out.extend_from_slice(&fnv(&payload).to_le_bytes());
            out.extend_from_slice(&payload);
            out
        }

        /// A snapshot from [`to_bytes`](Self::to_bytes)' output, checked
        /// (header, checksum, decoding, [`World::validate`]).
        pub fn from_bytes(bytes: &[u8]) -> Result<Snapshot, SnapshotError> {
            if bytes.len() < HEADER {
                return Err(SnapshotError::Truncated {
                    needed: HEADER,
                    found: bytes.len(),
                });
            }
            if bytes[0..4] != SNAPSHOT_MAGIC {
                return Err(SnapshotError::BadMagic);
            }
            let version = u16::from_le_bytes([bytes[4], bytes[5]]);
            if version != SNAPSHOT_VERSION {
                return Err(SnapshotError::WrongVersion {
                    found: version,
                    expected: SNAPSHOT_VERSION,
                });
            }
            if (bytes[6], bytes[7]) != build_bytes() {
                return Err(SnapshotError::WrongBuild {
                    real_bytes: bytes[6],
                    portals: bytes[7] != 0,
                });
            }
            let word = |k: usize| {
                let mut w = [0u8; 8];
                w.copy_from_slice(&bytes[k..k + 8]);
                u64::from_le_bytes(w)
            };
            let len = usize::try_from(word(8)).unwrap_or(usize::MAX);
            let payload = &bytes[HEADER..];
            if payload.len() < len {
                return Err(SnapshotError::Truncated {
                    needed: HEADER.saturating_add(len),
                    found: bytes.len(),
                });
            }
            if payload.len() > len {
                return Err(SnapshotError::TrailingBytes {
                    extra: payload.len() - len,
                });
            }
            if fnv(payload) != word(16) {
                return Err(SnapshotError::Checksum);
            }
            let mut world: World =
                postcard::from_bytes(payload).map_err(|e| SnapshotError::Decode(e.to_string()))?;
            world.validate().map_err(SnapshotError::Invalid)?;
            // The trees' filter bits are not in the bytes: from the shapes.
            world.collision.refresh_filter_bits();
            Ok(Snapshot {
                world: Box::new(world),
            })
        }
    }
}
