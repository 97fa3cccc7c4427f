//! Union–find over dense `u32` indices (path halving), shared by the sleep
//! islands and the joint forest.
//!
//! `parent[i] == i` marks a root; start with `parent = 0..n`.

/// The root of `i`'s set, halving the path on the way.
#[inline]
pub fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let up = parent[parent[i as usize] as usize];
        parent[i as usize] = up;
        i = up;
    }
    i
}

/// Joins the sets of `a` and `b`. The smaller root index becomes the root
/// (deterministic whatever the order of the calls). Returns `(root,
/// absorbed)` when two sets were joined, `None` when `a` and `b` were
/// already in the same set.
#[inline]
pub fn union(parent: &mut [u32], a: u32, b: u32) -> Option<(u32, u32)> {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra == rb {
        return None;
    }
    let (root, absorbed) = if ra < rb { (ra, rb) } else { (rb, ra) };
    parent[absorbed as usize] = root;
    Some((root, absorbed))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joins_and_reports_loops() {
        let mut p: Vec<u32> = (0..5).collect();
        assert_eq!(union(&mut p, 3, 1), Some((1, 3)));
        assert_eq!(union(&mut p, 1, 4), Some((1, 4)));
        assert_eq!(union(&mut p, 4, 3), None, "already joined: a loop");
        assert_eq!(find(&mut p, 4), 1);
        assert_eq!(find(&mut p, 0), 0);
        assert_eq!(find(&mut p, 2), 2);
    }
}
