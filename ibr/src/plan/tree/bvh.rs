//! The hierarchy over a scene's objects: a bounding volume hierarchy of axis-aligned boxes,
//! built once by median splits along the longest axis of the boxes' centres, and refitted
//! where objects move (only the nodes on the path from a moved object's leaf to the root).
//!
//! Nodes are numbered in depth-first pre-order (the root 0, a parent before its children),
//! so a refit recomputes touched nodes in descending order, children before parents. Each
//! node's objects are one contiguous range of [`Tree::order`]; each node has a version,
//! bumped whenever a refit passes through it, so images of it know they are stale.

use engine::Sphere;
use glam::Vec3;

/// No child: the node is a leaf.
pub const NONE: u32 = u32::MAX;

/// One node of the hierarchy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node {
    /// The box around its objects' boxes, world space: its least corner,
    pub lo: Vec3,
    /// and its greatest.
    pub hi: Vec3,
    /// Its two children ([`NONE`] for a leaf).
    pub children: [u32; 2],
    /// Its parent ([`NONE`] for the root).
    pub parent: u32,
    /// Its objects are `order[first..first + count]`: the first,
    pub first: u32,
    /// and how many.
    pub count: u32,
    /// Bumped by every refit that passes through it.
    pub version: u64,
}

impl Node {
    /// Whether it has no children.
    pub fn is_leaf(&self) -> bool {
        self.children[0] == NONE
    }

    /// The sphere around its box.
    pub fn sphere(&self) -> Sphere {
        Sphere {
            center: (self.lo + self.hi) * 0.5,
            radius: ((self.hi - self.lo) * 0.5).length().max(1e-6),
        }
    }
}

/// A bounding volume hierarchy over objects' boxes.
#[derive(Clone, Debug, Default)]
pub struct Tree {
    nodes: Vec<Node>,
    order: Vec<u32>,
    /// Each object's box and leaf.
    boxes: Vec<(Vec3, Vec3)>,
    leaf_of: Vec<u32>,
    /// Per node, the refit that last touched it (dedupes a refit's paths).
    stamp: Vec<u32>,
    refits: u32,
    touched: Vec<u32>,
}

impl Tree {
    /// The hierarchy over `boxes` (one per object; a box with a non-finite corner is taken
    /// as the point at the origin), at most `leaf` objects per leaf (at least 1).
    pub fn build(boxes: &[(Vec3, Vec3)], leaf: usize) -> Tree {
        let leaf = leaf.max(1);
        let boxes: Vec<(Vec3, Vec3)> = boxes
            .iter()
            .map(|&(lo, hi)| {
                if lo.is_finite() && hi.is_finite() {
                    (lo.min(hi), hi.max(lo))
                } else {
                    (Vec3::ZERO, Vec3::ZERO)
                }
            })
            .collect();
        let n = boxes.len();
        let mut tree = Tree {
            nodes: Vec::with_capacity(2 * n.div_ceil(leaf)),
            order: (0..n as u32).collect(),
            leaf_of: vec![NONE; n],
            boxes,
            ..Tree::default()
        };
        if n > 0 {
            tree.split(0, n, NONE, leaf);
        }
        tree.stamp = vec![0; tree.nodes.len()];
        tree
    }

    /// Makes the node over `order[first..first + count]` and its subtree; returns its index.
    fn split(&mut self, first: usize, count: usize, parent: u32, leaf: usize) -> u32 {
        let k = self.nodes.len() as u32;
        let (lo, hi) = self.enclose(first, count);
        self.nodes.push(Node {
            lo,
            hi,
            children: [NONE; 2],
            parent,
            first: first as u32,
            count: count as u32,
            version: 0,
        });
        if count <= leaf {
            for &i in &self.order[first..first + count] {
                self.leaf_of[i as usize] = k;
            }
            return k;
        }
        // The longest axis of the centres' box; the median by centre along it (ties by
        // object index, so the same boxes make the same tree).
        let centre = |b: &(Vec3, Vec3)| (b.0 + b.1) * 0.5;
        let range = &self.order[first..first + count];
        let (clo, chi) = range.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(l, h), &i| {
                let c = centre(&self.boxes[i as usize]);
                (l.min(c), h.max(c))
            },
        );
        let ext = chi - clo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let boxes = &self.boxes;
        let half = count / 2;
        self.order[first..first + count].select_nth_unstable_by(half, |&a, &b| {
            let (ca, cb) = (centre(&boxes[a as usize]), centre(&boxes[b as usize]));
            ca[axis].total_cmp(&cb[axis]).then(a.cmp(&b))
        });
        let left = self.split(first, half, k, leaf);
        let right = self.split(first + half, count - half, k, leaf);
        self.nodes[k as usize].children = [left, right];
        k
    }

    /// The box around the boxes of `order[first..first + count]`.
    fn enclose(&self, first: usize, count: usize) -> (Vec3, Vec3) {
        self.order[first..first + count].iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(l, h), &i| {
                let b = self.boxes[i as usize];
                (l.min(b.0), h.max(b.1))
            },
        )
    }

    /// Gives the objects `moved` their new boxes and refits the nodes on their paths to the
    /// root (each once, children before parents), bumping their versions. Objects out of
    /// range are ignored. Returns the nodes refitted, ascending (what images of them must
    /// be retaken for); every other node is untouched.
    pub fn refit(&mut self, moved: &[(usize, (Vec3, Vec3))]) -> &[u32] {
        self.refits = self.refits.wrapping_add(1).max(1);
        self.touched.clear();
        for &(i, (lo, hi)) in moved {
            if i >= self.boxes.len() {
                continue;
            }
            self.boxes[i] = if lo.is_finite() && hi.is_finite() {
                (lo.min(hi), hi.max(lo))
            } else {
                (Vec3::ZERO, Vec3::ZERO)
            };
            let mut k = self.leaf_of[i];
            while k != NONE && self.stamp[k as usize] != self.refits {
                self.stamp[k as usize] = self.refits;
                self.touched.push(k);
                k = self.nodes[k as usize].parent;
            }
        }
        // Pre-order: every child after its parent, so descending is bottom-up.
        self.touched.sort_unstable_by(|a, b| b.cmp(a));
        for t in 0..self.touched.len() {
            let k = self.touched[t] as usize;
            let node = self.nodes[k];
            let (lo, hi) = if node.is_leaf() {
                self.enclose(node.first as usize, node.count as usize)
            } else {
                let [a, b] = node.children.map(|c| self.nodes[c as usize]);
                (a.lo.min(b.lo), a.hi.max(b.hi))
            };
            let n = &mut self.nodes[k];
            (n.lo, n.hi) = (lo, hi);
            n.version += 1;
        }
        self.touched.reverse();
        &self.touched
    }

    /// The nodes, the root first.
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// Node `k`'s objects.
    pub fn objects_of(&self, k: usize) -> &[u32] {
        let n = &self.nodes[k];
        &self.order[n.first as usize..(n.first + n.count) as usize]
    }

    /// Every object, in leaf order (each node's objects are a range of it).
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    /// The leaf holding object `i`.
    pub fn leaf_of(&self, i: usize) -> Option<u32> {
        self.leaf_of.get(i).copied()
    }

    /// Object `i`'s box as last given.
    pub fn box_of(&self, i: usize) -> Option<(Vec3, Vec3)> {
        self.boxes.get(i).copied()
    }
}
