//! The attraction meter's per-frame buffers: one measured frame's renders read out of its
//! targets as premultiplied RGBA8 with its mask ([`Renders`]), into storage kept frame to
//! frame, and the flicker's change between two of them ([`change`]).

use engine::Target;

/// One measured frame's image and geometry renders (premultiplied RGBA8, row-major, as
/// [`Target::to_rgba8_premultiplied`] gives them) and its mask. Refilled in place
/// ([`Renders::fill`]): a meter trades these between its scratch and its tracks' last
/// frames, so after every track has measured once no frame allocates (until the size
/// changes).
#[derive(Clone, Debug, Default)]
pub(crate) struct Renders {
    pub image: Vec<u8>,
    pub truth: Vec<u8>,
    pub mask: Vec<bool>,
}

/// Rows read out of a target, and the occluder's bytes, kept frame to frame.
#[derive(Debug, Default)]
pub(crate) struct Reader {
    row: Vec<u32>,
    depth: Vec<f32>,
    base: Vec<u8>,
}

impl Reader {
    /// `t`'s stored bytes (premultiplied RGBA8), row-major, top row first, into `out`
    /// (cleared first): the bytes of [`Target::to_rgba8_premultiplied`], into a kept buffer.
    pub(crate) fn read(&mut self, t: &Target, out: &mut Vec<u8>) {
        out.clear();
        for y in 0..t.height() {
            t.read_row(y, &mut self.row, &mut self.depth);
            out.extend(self.row.iter().flat_map(|p| p.to_le_bytes()));
        }
    }

    /// Bytes held (capacities), for the tests that check nothing grows frame to frame.
    pub(crate) fn held(&self) -> usize {
        self.row.capacity() * 4 + self.depth.capacity() * 4 + self.base.capacity()
    }
}

impl Renders {
    /// The renders and their mask: where either is covered, or with `base` (the occluder
    /// alone), where either differs from it.
    pub(crate) fn fill(
        &mut self,
        image: &Target,
        truth: &Target,
        base: Option<&Target>,
        reader: &mut Reader,
    ) {
        reader.read(image, &mut self.image);
        reader.read(truth, &mut self.truth);
        let (image, truth) = (&self.image, &self.truth);
        self.mask.clear();
        match base {
            Some(b) => {
                let mut bytes = std::mem::take(&mut reader.base);
                reader.read(b, &mut bytes);
                self.mask.extend(
                    (0..bytes.len() / 4)
                        .map(|i| px(image, i) != px(&bytes, i) || px(truth, i) != px(&bytes, i)),
                );
                reader.base = bytes;
            }
            None => self
                .mask
                .extend((0..image.len() / 4).map(|i| px(image, i)[3] > 0 || px(truth, i)[3] > 0)),
        }
    }

    /// Bytes held (capacities).
    pub(crate) fn held(&self) -> usize {
        self.image.capacity() + self.truth.capacity() + self.mask.capacity()
    }
}

pub(crate) fn px(b: &[u8], i: usize) -> &[u8] {
    &b[4 * i..4 * i + 4]
}

/// Summed mean-RGB absolute change of the image and of the geometry from `prev` to `now`,
/// over the union of their masks, and that union's pixel count.
pub(crate) fn change(prev: &Renders, now: &Renders) -> (f64, f64, f64) {
    let diff = |a: &[u8], b: &[u8]| (0..3).map(|c| a[c].abs_diff(b[c]) as f64).sum::<f64>() / 3.0;
    let (mut di, mut dt, mut m) = (0.0, 0.0, 0.0);
    let masks = prev.mask.iter().zip(&now.mask);
    for (i, _) in masks.enumerate().filter(|(_, (a, b))| **a || **b) {
        di += diff(px(&prev.image, i), px(&now.image, i));
        dt += diff(px(&prev.truth, i), px(&now.truth, i));
        m += 1.0;
    }
    (di, dt, m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use engine::Rgba;

    /// The bytes read into a kept buffer are the target's own copy's, and reading again
    /// at the same size keeps the buffer's storage.
    #[test]
    fn reading_a_target_gives_its_bytes_into_the_same_storage() {
        let mut t = Target::new(37, 21);
        t.clear(Rgba::new(0.2, 0.4, 0.6, 0.8));
        let mut reader = Reader::default();
        let mut out = Vec::new();
        reader.read(&t, &mut out);
        assert_eq!(out, t.to_rgba8_premultiplied());
        let (ptr, cap) = (out.as_ptr(), out.capacity());
        t.clear(Rgba::new(0.9, 0.1, 0.0, 1.0));
        reader.read(&t, &mut out);
        assert_eq!(out, t.to_rgba8_premultiplied());
        assert_eq!((out.as_ptr(), out.capacity()), (ptr, cap));
    }
}
