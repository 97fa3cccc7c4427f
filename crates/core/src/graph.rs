//! Graph colouring of constraints over the bodies they move.
//!
//! Two constraints of one colour never share a body whose state the solve
//! changes, so a colour's constraints can be solved in any order, in SIMD
//! lanes or on separate threads, with the result of a sequential sweep.
//! Static and kinematic bodies take no colour: the solve reads their state
//! but never changes it.
//!
//! ```text
//!   constraint      bodies        colour bits (a | b)   colour
//!   c0              1, 2          0000 | 0000           0
//!   c1              2, 3          0001 | 0000           1
//!   c2              3, ground     0010 | -              0
//!   c3              1, 3          0001 | 0011           2
//! ```
//!
//! Colouring is greedy in the order constraints are offered (the lowest
//! free colour); a constraint whose bodies already use all [`COLOURS`]
//! colours goes to the overflow set, solved one by one.

/// Number of colours.
pub const COLOURS: usize = 24;

/// The colour bits of every body state for one step's colouring.
#[derive(Clone, Debug, Default)]
pub struct ColourGraph {
    /// Bit `c` set: the body already appears in colour `c`.
    body_colours: Vec<u32>,
}

impl ColourGraph {
    /// An empty graph.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Clears every body's colours, for `state_count` body states.
    pub fn reset(&mut self, state_count: usize) {
        self.body_colours.clear();
        self.body_colours.resize(state_count, 0);
    }

    /// Assigns the lowest colour in which neither body appears and marks
    /// both in it; `None` for a body means it takes no colour (static or
    /// kinematic). Returns `None` when no colour is free (overflow), or
    /// when a state index is out of range.
    pub fn assign(&mut self, a: Option<u32>, b: Option<u32>) -> Option<usize> {
        let bits = |i: Option<u32>, colours: &[u32]| match i {
            Some(i) => colours.get(i as usize).copied(),
            None => Some(0),
        };
        let used = bits(a, &self.body_colours)? | bits(b, &self.body_colours)?;
        let colour = (!used).trailing_zeros() as usize;
        if colour >= COLOURS {
            return None;
        }
        for i in [a, b].into_iter().flatten() {
            self.body_colours[i as usize] |= 1 << colour;
        }
        Some(colour)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_colour_never_holds_a_moving_body_twice() {
        let mut g = ColourGraph::new();
        g.reset(4);
        assert_eq!(g.assign(Some(1), Some(2)), Some(0));
        assert_eq!(g.assign(Some(2), Some(3)), Some(1));
        assert_eq!(g.assign(Some(3), None), Some(0));
        assert_eq!(g.assign(Some(1), Some(3)), Some(2));
        // Bodies that take no colour never block one.
        assert_eq!(g.assign(None, None), Some(0));
    }

    #[test]
    fn a_body_in_every_colour_overflows() {
        let mut g = ColourGraph::new();
        g.reset(COLOURS + 2);
        for k in 0..COLOURS {
            assert_eq!(g.assign(Some(0), Some(k as u32 + 1)), Some(k));
        }
        assert_eq!(g.assign(Some(0), Some(COLOURS as u32 + 1)), None);
        assert_eq!(g.assign(Some(99), None), None, "out of range");
    }
}
