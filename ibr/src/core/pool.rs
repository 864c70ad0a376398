//! The impostor texture pool: square power-of-two textures, each with the material that
//! draws it, handed out to impostors and taken back, so refreshing an impostor rewrites an
//! existing texture instead of allocating one.

use engine::{AlphaMode, BlendMode, Encoding, Filter, Material, Rgba, Sampler, Texture, Wrap};
use std::sync::Arc;

/// One pooled texture and its material (the material holds the only `Arc` to the texture,
/// so the pool can rewrite it in place).
#[derive(Debug)]
struct Slot {
    side: u32,
    material: Material,
    in_use: bool,
}

/// A bounded set of impostor textures.
#[derive(Debug)]
pub struct Pool {
    slots: Vec<Slot>,
    /// The most textures the pool will hold.
    pub max_slots: usize,
}

impl Pool {
    /// An empty pool that will hold at most `max_slots` textures.
    pub fn new(max_slots: usize) -> Self {
        Pool {
            slots: Vec::new(),
            max_slots,
        }
    }

    /// A free texture for a `side` x `side` image: a free one of that size, else a new one
    /// (a placeholder until its refresh swaps the image in) while the pool has room, else a
    /// free one of another size (resized on its next refill). `None` when every texture is
    /// in use and the pool is full.
    pub fn acquire(&mut self, side: u32) -> Option<usize> {
        let free = |s: &Slot| !s.in_use;
        let pick = self
            .slots
            .iter()
            .position(|s| free(s) && s.side == side)
            .or_else(|| {
                (self.slots.len() < self.max_slots).then(|| {
                    // A 1 x 1 placeholder: every refresh swaps its own texture in
                    // ([`Pool::swap_texture`]) before the slot is drawn, so a transparent
                    // `side` x `side` texture built here (its mips and linear copy) was
                    // built only to be traded away; in the world's fly-over, where nearly
                    // every node capture took a new slot, that was a fifth of a capture's
                    // time (`perf record`, session 18).
                    self.slots.push(Slot {
                        side,
                        material: image_material(1, 1, "impostor"),
                        in_use: false,
                    });
                    self.slots.len() - 1
                })
            })
            .or_else(|| self.slots.iter().position(free))?;
        self.slots[pick].in_use = true;
        Some(pick)
    }

    /// Returns `slot` to the pool (its texture is kept for reuse); unknown slots are ignored.
    pub fn release(&mut self, slot: usize) {
        if let Some(s) = self.slots.get_mut(slot) {
            s.in_use = false;
        }
    }

    /// Puts `tex` in `slot` and hands back the texture it held, so the refresh that
    /// filled `tex` gets the old one's memory to fill next time (the pool's material holds
    /// the only reference, so this succeeds for every slot the pool made); `false`, with
    /// nothing swapped, for another slot.
    pub fn swap_texture(&mut self, slot: usize, tex: &mut Texture) -> bool {
        let Some(s) = self.slots.get_mut(slot) else {
            return false;
        };
        let Some(held) = s.material.base_texture.as_mut().and_then(Arc::get_mut) else {
            return false;
        };
        std::mem::swap(held, tex);
        s.side = held.width();
        true
    }

    /// The material drawing `slot`'s texture, `None` for an unknown slot.
    pub fn material(&self, slot: usize) -> Option<&Material> {
        self.slots.get(slot).map(|s| &s.material)
    }

    /// Sets the tint of `slot`'s material (the debug view colours impostors by error).
    pub fn set_tint(&mut self, slot: usize, tint: Rgba) {
        if let Some(s) = self.slots.get_mut(slot) {
            s.material.base_color = tint;
        }
    }

    /// Sets how `slot`'s material uses its image's alpha (blended by default; a cutout,
    /// [`AlphaMode::Mask`], keeps the pixels more than the cutoff covered, as geometry's).
    pub fn set_alpha(&mut self, slot: usize, alpha: AlphaMode) {
        if let Some(s) = self.slots.get_mut(slot) {
            s.material.alpha_mode = alpha;
        }
    }

    /// Textures in use and in the pool.
    pub fn usage(&self) -> (usize, usize) {
        (
            self.slots.iter().filter(|s| s.in_use).count(),
            self.slots.len(),
        )
    }

    /// Bytes of texel memory held (level 0 and mips, packed colour and the linear copy).
    pub fn bytes(&self) -> usize {
        self.slots
            .iter()
            .map(|s| (s.side as usize).pow(2) * 12 * 4 / 3)
            .sum()
    }
}

/// The alpha from which an image drawn in place of an opaque object writes depth
/// ([`engine::Material::blend_depth`]): what reads the depth after it sees the object
/// where it is more than half covered.
pub(crate) const IMAGE_DEPTH_ALPHA: f32 = 0.5;

/// The material that draws an image in place of geometry (an impostor's, an image
/// layer's): its premultiplied image, alpha-blended, writing depth where more than half
/// covered (`IMAGE_DEPTH_ALPHA`), unlit, clamped at the edges, seen from either side; a
/// transparent `width` x `height` texture until it is filled.
pub fn image_material(width: u32, height: u32, name: &str) -> Material {
    let (w, h) = (width.max(1), height.max(1));
    let texture =
        Texture::from_packed(w, h, vec![0; w as usize * h as usize], Encoding::Srgb, true)
            .expect("a rectangle of at least 1 texel");
    let mut m = Material::unlit(Rgba::WHITE)
        .with_texture(Arc::new(texture))
        .blended(BlendMode::Alpha)
        .double_sided(true);
    m.vertex_colors = false;
    m.blend_depth = Some(IMAGE_DEPTH_ALPHA);
    // Bilinear: the resolution predictor keeps the texture near the screen size, where a
    // trilinear blend toward the next mip would only blur.
    m.sampler = Sampler {
        wrap_u: Wrap::Clamp,
        wrap_v: Wrap::Clamp,
        filter: Filter::Bilinear,
    };
    m.name = name.into();
    m
}
