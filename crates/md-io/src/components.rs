//! Connected parts by union-find with path halving: joined elements share a root, and a part's
//! root is its lowest element (so parts come out in order of their first element). Used for
//! clusters of neighbours (`coordination`), single-linkage clusters of frames (`conformations`)
//! and leaflets (`membrane`).

/// The parts of elements `0..n` as they are joined.
pub(crate) struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    /// `n` elements, each its own part.
    pub(crate) fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    /// The root of `i`'s part: its lowest element.
    pub(crate) fn root(&mut self, i: usize) -> usize {
        let mut i = i as u32;
        while self.parent[i as usize] != i {
            let p = self.parent[self.parent[i as usize] as usize];
            self.parent[i as usize] = p;
            i = p;
        }
        i as usize
    }

    /// Joins the parts of `a` and `b`.
    pub(crate) fn join(&mut self, a: usize, b: usize) {
        let (a, b) = (self.root(a), self.root(b));
        if a != b {
            self.parent[a.max(b)] = a.min(b) as u32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_are_rooted_at_their_lowest_element() {
        let mut u = UnionFind::new(6);
        u.join(4, 2);
        u.join(5, 4);
        u.join(3, 1);
        assert_eq!(
            (0..6).map(|i| u.root(i)).collect::<Vec<_>>(),
            [0, 1, 2, 1, 2, 2]
        );
        u.join(5, 1);
        assert_eq!(
            (0..6).map(|i| u.root(i)).collect::<Vec<_>>(),
            [0, 1, 1, 1, 1, 1]
        );
    }
}
