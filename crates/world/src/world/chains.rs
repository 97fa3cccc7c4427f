//! Chains: create, read, destroy (the definitions are `crate::chains`').

use super::*;
use crate::chains::{ChainData, ChainDef, ChainHandle};
use janus2d_core::body::BodyHandle;

impl World {
    /// Creates a chain on `body` (Box2D's `b2CreateChain`): one
    /// one-sided [`ChainSegment`](janus2d_core::geometry::ChainSegment)
    /// shape per segment, with the ghost vertices of
    /// [`make_chain`](janus2d_core::geometry::make_chain) and its own
    /// material. A bad definition ([`ChainDef::validate`]) or body is an
    /// error and changes nothing.
    ///
    /// ```
    /// use janus2d_world::{ChainDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let points = vec![Vec2::new(6.0, 0.0), Vec2::new(2.0, 0.0), Vec2::new(-2.0, 0.0), Vec2::new(-6.0, 0.0)];
    /// let chain = world.create_chain(ground, &ChainDef::new(points)).unwrap();
    /// assert_eq!(world.chain_segments(chain).unwrap().len(), 3);
    /// assert_eq!(world.chain_body(chain).unwrap(), ground);
    /// assert_eq!((world.chain_count(), world.shape_count()), (1, 3));
    /// ```
    pub fn create_chain(
        &mut self,
        body: BodyHandle,
        def: &ChainDef,
    ) -> Result<ChainHandle, WorldError> {
        self.check_body(body)?;
        def.validate()?;
        let pieces = janus2d_core::geometry::make_chain(&def.points, def.is_loop)?;
        for piece in &pieces {
            Shape::ChainSegment(*piece).validate()?;
        }
        let mut segments = Vec::with_capacity(pieces.len());
        for (i, piece) in pieces.iter().enumerate() {
            let shape_def = def.segment_def(i);
            match self.create_shape(body, &shape_def, Shape::ChainSegment(*piece)) {
                Ok(h) => segments.push(h),
                Err(e) => {
                    // Checked above: not reached; undo what was made.
                    for h in segments {
                        let _ = self.destroy_shape(h);
                    }
                    return Err(e);
                }
            }
        }
        let (index, generation) = self.collision.chains.slots.insert(ChainData {
            segments,
            is_loop: def.is_loop,
            user_data: def.user_data,
        });
        Ok(ChainHandle::new(index, generation, self.bodies.owner()))
    }

    fn chain_data(&self, chain: ChainHandle) -> Result<&ChainData, WorldError> {
        self.collision
            .chains
            .slots
            .resolve(chain, self.bodies.owner())
            .map_err(|e| WorldError::of_handle(e, WorldError::StaleChain))
    }

    /// The segment shapes of a chain, in segment order.
    ///
    /// ```
    /// use janus2d_world::{ChainDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Shape;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let square = vec![Vec2::new(0.0, 0.0), Vec2::new(0.0, 2.0), Vec2::new(2.0, 2.0), Vec2::new(2.0, 0.0)];
    /// let chain = world.create_chain(ground, &ChainDef::new(square).with_loop(true)).unwrap();
    /// let segments = world.chain_segments(chain).unwrap();
    /// assert_eq!(segments.len(), 4);
    /// assert!(matches!(world.shape(segments[0]).unwrap().geometry, Shape::ChainSegment(_)));
    /// ```
    pub fn chain_segments(&self, chain: ChainHandle) -> Result<&[ShapeHandle], WorldError> {
        self.chain_data(chain).map(|c| c.segments.as_slice())
    }

    /// The body a chain is on.
    ///
    /// ```
    /// use janus2d_world::{ChainDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let chain = world.create_chain(b, &ChainDef::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)])).unwrap();
    /// assert_eq!(world.chain_body(chain), Ok(b));
    /// ```
    pub fn chain_body(&self, chain: ChainHandle) -> Result<BodyHandle, WorldError> {
        let first = *self
            .chain_data(chain)?
            .segments
            .first()
            .ok_or(WorldError::StaleChain)?;
        self.shape_body(first)
    }

    /// Whether a chain is a loop.
    ///
    /// ```
    /// use janus2d_world::{ChainDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let chain = world.create_chain(b, &ChainDef::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)])).unwrap();
    /// assert_eq!(world.chain_is_loop(chain), Ok(false));
    /// ```
    pub fn chain_is_loop(&self, chain: ChainHandle) -> Result<bool, WorldError> {
        self.chain_data(chain).map(|c| c.is_loop)
    }

    /// A chain's opaque user value.
    ///
    /// ```
    /// use janus2d_world::{ChainDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let def = ChainDef::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)]).with_user_data(42);
    /// let chain = world.create_chain(b, &def).unwrap();
    /// assert_eq!(world.chain_user_data(chain), Ok(42));
    /// ```
    pub fn chain_user_data(&self, chain: ChainHandle) -> Result<u64, WorldError> {
        self.chain_data(chain).map(|c| c.user_data)
    }

    /// The chain a shape is a segment of, if any.
    ///
    /// ```
    /// use janus2d_world::{ChainDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let chain = world.create_chain(b, &ChainDef::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)])).unwrap();
    /// let s = world.chain_segments(chain).unwrap()[0];
    /// assert_eq!(world.shape_chain(s), Ok(Some(chain)));
    /// ```
    pub fn shape_chain(&self, shape: ShapeHandle) -> Result<Option<ChainHandle>, WorldError> {
        self.collision.shapes.slot(shape, self.bodies.owner())?;
        let owner = self.bodies.owner();
        Ok(self
            .collision
            .chains
            .chain_of_shape(shape)
            .map(|i| self.collision.chains.slots.handle(i, owner)))
    }

    /// Destroys a chain and its segment shapes (their contacts end, the
    /// body wakes). A stale handle is [`WorldError::StaleChain`].
    ///
    /// ```
    /// use janus2d_world::{ChainDef, World, WorldDef, WorldError};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let chain = world.create_chain(b, &ChainDef::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)])).unwrap();
    /// world.destroy_chain(chain).unwrap();
    /// assert_eq!((world.chain_count(), world.shape_count()), (0, 0));
    /// assert_eq!(world.destroy_chain(chain), Err(WorldError::StaleChain));
    /// ```
    pub fn destroy_chain(&mut self, chain: ChainHandle) -> Result<(), WorldError> {
        self.chain_data(chain)?;
        let data = self
            .collision
            .chains
            .slots
            .remove(chain.index, chain.generation)
            .ok_or(WorldError::StaleChain)?;
        for s in data.segments {
            let destroyed = self.destroy_shape(s);
            debug_assert!(destroyed.is_ok(), "a chain lists live shapes");
        }
        Ok(())
    }

    /// The number of chains.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// assert_eq!(World::new(WorldDef::default()).unwrap().chain_count(), 0);
    /// ```
    pub fn chain_count(&self) -> usize {
        self.collision.chains.slots.len()
    }

    /// The handles of every chain, in slot order.
    ///
    /// ```
    /// use janus2d_world::{ChainDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let chain = world.create_chain(b, &ChainDef::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)])).unwrap();
    /// assert_eq!(world.chain_handles(), vec![chain]);
    /// ```
    pub fn chain_handles(&self) -> Vec<ChainHandle> {
        let owner = self.bodies.owner();
        self.collision
            .chains
            .slots
            .iter()
            .map(|(i, _)| self.collision.chains.slots.handle(i, owner))
            .collect()
    }

    /// Checks the chains against the shapes (for [`World::validate`]):
    /// every chain has segments, each a live chain-segment shape of one
    /// body, listed by one chain only.
    pub(crate) fn check_chains(&self) -> Result<(), String> {
        let chains = &self.collision.chains.slots;
        chains.check().map_err(|e| format!("chain slots: {e}"))?;
        let owner = self.bodies.owner();
        let mut seen = std::collections::HashSet::new();
        for (i, chain) in chains.iter() {
            let expected = chain.segments.len();
            if expected == 0 {
                return Err(format!("chain {i}: no segments"));
            }
            let mut body = None;
            for &s in &chain.segments {
                let slot = self
                    .collision
                    .shapes
                    .slot(s, owner)
                    .map_err(|_| format!("chain {i}: segment {s:?} is not a live shape"))?;
                let data = self.collision.shapes.at(slot);
                if !matches!(data.geometry, Shape::ChainSegment(_)) {
                    return Err(format!("chain {i}: shape {s:?} is not a chain segment"));
                }
                if *body.get_or_insert(data.body) != data.body {
                    return Err(format!("chain {i}: segments on two bodies"));
                }
                if !seen.insert(s) {
                    return Err(format!("chain {i}: shape {s:?} listed twice"));
                }
            }
        }
        Ok(())
    }
}
