//! Generational slots: the storage behind handles.
//!
//! ```text
//! insert ─▶ (index, generation)       remove ─▶ slot freed, generation kept
//! get(index, generation) ─▶ Some only while the generation matches
//! ```
//!
//! A removed slot is reused by the next insert with its generation bumped,
//! so a handle to what was removed is stale, never aliased. Slots are
//! visited in index order (deterministic).

/// Values in generational slots.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Slots<T> {
    entries: Vec<(u32, Option<T>)>,
    free: Vec<u32>,
    live: usize,
}

impl<T> Default for Slots<T> {
    fn default() -> Self {
        Slots {
            entries: Vec::new(),
            free: Vec::new(),
            live: 0,
        }
    }
}

impl<T> Slots<T> {
    /// Stores a value; returns its `(index, generation)`.
    ///
    /// ```
    /// use janus2d_core::slots::Slots;
    /// let mut s = Slots::default();
    /// let (i, g) = s.insert("a");
    /// assert_eq!(s.remove(i, g), Some("a"));
    /// let (j, h) = s.insert("b");
    /// assert_eq!(j, i);
    /// assert!(s.get(i, g).is_none() && s.get(j, h) == Some(&"b"));
    /// ```
    pub fn insert(&mut self, value: T) -> (u32, u32) {
        self.live += 1;
        match self.free.pop() {
            Some(i) => {
                let e = &mut self.entries[i as usize];
                e.0 = e.0.wrapping_add(1);
                e.1 = Some(value);
                (i, e.0)
            }
            None => {
                self.entries.push((1, Some(value)));
                ((self.entries.len() - 1) as u32, 1)
            }
        }
    }

    /// The value in a live slot whose generation matches.
    pub fn get(&self, index: u32, generation: u32) -> Option<&T> {
        match self.entries.get(index as usize) {
            Some((g, Some(v))) if *g == generation => Some(v),
            _ => None,
        }
    }

    /// Mutable access to a live slot whose generation matches.
    pub fn get_mut(&mut self, index: u32, generation: u32) -> Option<&mut T> {
        match self.entries.get_mut(index as usize) {
            Some((g, Some(v))) if *g == generation => Some(v),
            _ => None,
        }
    }

    /// Asks the cache for slot `index`'s line ahead of a read of it
    /// ([`crate::hint::prefetch`]); reads nothing of the slot itself.
    #[inline(always)]
    pub fn prefetch(&self, index: u32) {
        if let Some(entry) = self.entries.get(index as usize) {
            crate::hint::prefetch(&entry.1);
        }
    }

    /// The value in slot `index` if it is live (any generation).
    pub fn at(&self, index: u32) -> Option<&T> {
        self.entries.get(index as usize).and_then(|e| e.1.as_ref())
    }

    /// The value in live slot `index`; for indices the store itself handed
    /// out (a free slot here is a bug in the caller, not user input).
    ///
    /// # Panics
    /// When slot `index` is free.
    #[inline]
    #[track_caller]
    pub fn live(&self, index: u32) -> &T {
        self.entries[index as usize]
            .1
            .as_ref()
            .expect("slot index handed out by this store")
    }

    /// Mutable access to live slot `index`; see [`Slots::live`].
    ///
    /// # Panics
    /// When slot `index` is free.
    #[inline]
    #[track_caller]
    pub fn live_mut(&mut self, index: u32) -> &mut T {
        self.entries[index as usize]
            .1
            .as_mut()
            .expect("slot index handed out by this store")
    }

    /// Every slot by index as `(generation, value)` (`None`: free), for a
    /// pass that splits the slots among threads (a
    /// [`Team`](crate::parallel::Team)'s blocks). A pass may change the
    /// live values; it must leave every generation, and which slots are
    /// free, as it found them.
    pub fn entries_mut(&mut self) -> &mut [(u32, Option<T>)] {
        &mut self.entries
    }

    /// Mutable access to slot `index` if it is live (any generation).
    pub fn at_mut(&mut self, index: u32) -> Option<&mut T> {
        self.entries
            .get_mut(index as usize)
            .and_then(|e| e.1.as_mut())
    }

    /// The current generation of slot `index` (0 if never used).
    pub fn generation(&self, index: u32) -> u32 {
        self.entries.get(index as usize).map_or(0, |e| e.0)
    }

    /// Frees a slot whose generation matches; returns its value.
    pub fn remove(&mut self, index: u32, generation: u32) -> Option<T> {
        let e = self.entries.get_mut(index as usize)?;
        if e.0 != generation || e.1.is_none() {
            return None;
        }
        self.free.push(index);
        self.live -= 1;
        e.1.take()
    }

    /// Number of live values.
    pub fn len(&self) -> usize {
        self.live
    }

    /// True when no value is stored.
    pub fn is_empty(&self) -> bool {
        self.live == 0
    }

    /// One past the largest index ever used.
    pub fn capacity(&self) -> u32 {
        self.entries.len() as u32
    }

    /// The value a handle refers to, checking its world and generation.
    pub fn resolve<K>(
        &self,
        handle: crate::handle::Handle<K>,
        owner: u32,
    ) -> Result<&T, crate::handle::HandleError> {
        if handle.owner != owner {
            return Err(crate::handle::HandleError::Foreign);
        }
        self.get(handle.index, handle.generation)
            .ok_or(crate::handle::HandleError::Stale)
    }

    /// The handle of live slot `index` in world `owner`.
    #[must_use]
    pub fn handle<K>(&self, index: u32, owner: u32) -> crate::handle::Handle<K> {
        crate::handle::Handle::new(index, self.generation(index), owner)
    }

    /// Checks the store's own bookkeeping (for a world's validator, after
    /// decoding a snapshot): the live count matches the live slots, and the
    /// free list holds every free slot exactly once and nothing else.
    ///
    /// ```
    /// use janus2d_core::slots::Slots;
    /// let mut s = Slots::default();
    /// let (i, g) = s.insert(1);
    /// s.insert(2);
    /// s.remove(i, g);
    /// assert_eq!(s.check(), Ok(()));
    /// ```
    pub fn check(&self) -> Result<(), String> {
        let live = self.entries.iter().filter(|e| e.1.is_some()).count();
        if live != self.live {
            return Err(format!("{live} live slots, count says {}", self.live));
        }
        if self.free.len() != self.entries.len() - live {
            return Err(format!(
                "{} free slots, free list holds {}",
                self.entries.len() - live,
                self.free.len()
            ));
        }
        let mut seen = vec![false; self.entries.len()];
        for &i in &self.free {
            match self.entries.get(i as usize) {
                Some((_, None)) if !seen[i as usize] => seen[i as usize] = true,
                _ => return Err(format!("free list entry {i} is not a free slot once")),
            }
        }
        Ok(())
    }

    /// Live values with their index, in index order.
    pub fn iter(&self) -> impl Iterator<Item = (u32, &T)> {
        self.entries
            .iter()
            .enumerate()
            .filter_map(|(i, e)| e.1.as_ref().map(|v| (i as u32, v)))
    }
}
