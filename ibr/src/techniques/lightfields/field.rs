//! A captured light slab and its rays (raw packed samples with their depths, or quantised),
//! captured on both cores.

use super::*;

/// A captured light slab: its geometry and its rays.
#[derive(Clone, Debug)]
pub struct LightField {
    /// Where the rays are: the two planes and the sample counts.
    pub slab: Slab,
    /// The samples, `slab.len()` of them.
    pub rays: Rays,
}

/// A light field's samples: as captured, or vector-quantised.
#[derive(Clone, Debug)]
pub enum Rays {
    /// One packed colour (and optionally one depth) per ray, as captured.
    Raw(RawRays),
    /// Vector-quantised: a codebook of 4D tiles and one codeword index per tile.
    Quantised(Quantised),
}

/// Samples as captured, one per ray.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RawRays {
    /// Packed colour ([`ENCODING`]) of sample `(u, v, s, t)` at
    /// `((v nu + u) nt + t) ns + s`: image after image.
    pub samples: Vec<u32>,
    /// Per sample, in the same order, the distance along [`Slab::forward`] from the `uv`
    /// plane to the surface its ray met (infinite where it met none): the proxy of depth
    /// correction. Empty when not kept.
    pub depth: Vec<f32>,
    /// The nearest and farthest finite depth, found when first asked for.
    range: OnceLock<Option<(f32, f32)>>,
}

impl RawRays {
    /// Samples and their depths (empty when not kept).
    pub fn new(samples: Vec<u32>, depth: Vec<f32>) -> Self {
        RawRays {
            samples,
            depth,
            range: OnceLock::new(),
        }
    }

    /// The nearest and farthest surface any ray met (distances from the `uv` plane);
    /// `None` when none met one or depth is not kept. Found once, on first use: change
    /// `depth` only before rendering.
    pub fn depth_range(&self) -> Option<(f32, f32)> {
        *self.range.get_or_init(|| depth_range(&self.depth))
    }

    /// Whether depths are kept.
    pub fn has_depth(&self) -> bool {
        self.depth.len() == self.samples.len()
    }

    #[inline]
    pub(crate) fn index(&self, [nu, _, ns, nt]: [u32; 4], u: u32, v: u32, s: u32, t: u32) -> usize {
        ((v as usize * nu as usize + u as usize) * nt as usize + t as usize) * ns as usize
            + s as usize
    }
}

impl LightField {
    /// Captures `draws` (lit by `lighting`) through `slab`: one image per `uv` sample, on
    /// the thread pool; the same samples at any thread count.
    pub fn capture(draws: &[Draw<'_>], lighting: &Lighting, slab: Slab) -> LightField {
        Self::capture_with_progress(draws, lighting, slab, &mut |_, _| {})
    }

    /// [`LightField::capture`], calling `progress(done, total)` with the images captured
    /// so far after each row of cameras.
    pub fn capture_with_progress(
        draws: &[Draw<'_>],
        lighting: &Lighting,
        slab: Slab,
        progress: &mut dyn FnMut(usize, usize),
    ) -> LightField {
        Self::capture_prefiltered(draws, lighting, slab, 1, progress)
    }

    /// A capture prefiltered over the aperture (Levoy and Hanrahan 96, section 3.2): each
    /// `uv` sample's image is the mean of `aperture` x `aperture` images from cameras
    /// spread evenly over its cell of the `uv` plane, all framing the `st` rectangle, so
    /// what lies off the focal plane is blurred by the cell's aperture instead of aliasing
    /// into ghosts between cameras; what lies in the focal plane is unchanged. Colour is
    /// averaged premultiplied and linear; a sample's depth is the mean of the finite depths
    /// its views saw (infinite when none saw anything; none kept when a plane is at
    /// infinity). `aperture` 1 (or 0) is the plain capture.
    pub fn capture_prefiltered(
        draws: &[Draw<'_>],
        lighting: &Lighting,
        slab: Slab,
        aperture: u32,
        progress: &mut dyn FnMut(usize, usize),
    ) -> LightField {
        Self::capture_filtered(draws, lighting, slab, [aperture, 1], progress)
    }

    /// A capture with coverage (an alpha channel for the silhouette): each camera's image
    /// rendered `supersample` times finer along `s` and `t` and each sample the mean of
    /// its `supersample` x `supersample` sub-samples, premultiplied and linear, so a
    /// sample on an outline holds the share of its cell the object covers and the
    /// outline can be found between samples ([`super::LightFieldObject::hard_edges`]).
    /// A sample's depth is the mean of the finite depths its sub-samples saw. The
    /// samples and the memory are those of the plain capture; the rendering is
    /// `supersample` squared times. `supersample` 1 (or 0) is the plain capture.
    pub fn capture_supersampled(
        draws: &[Draw<'_>],
        lighting: &Lighting,
        slab: Slab,
        supersample: u32,
    ) -> LightField {
        Self::capture_filtered(draws, lighting, slab, [1, supersample], &mut |_, _| {})
    }

    /// Each sample the mean over `aperture` x `aperture` views spread over its camera's
    /// cell ([`LightField::capture_prefiltered`]) and `supersample` x `supersample`
    /// sub-samples of its `st` cell ([`LightField::capture_supersampled`]).
    fn capture_filtered(
        draws: &[Draw<'_>],
        lighting: &Lighting,
        slab: Slab,
        [aperture, supersample]: [u32; 2],
        progress: &mut dyn FnMut(usize, usize),
    ) -> LightField {
        let n = aperture.max(1);
        let k = supersample.max(1) as usize;
        let enc = Encoder::new(ENCODING);
        let mut samples = Vec::with_capacity(slab.len());
        let mut depth = Vec::with_capacity(slab.len());
        let total = slab.nu as usize * slab.nv as usize;
        let (ns, nt) = (slab.ns as usize, slab.nt as usize);
        let per_image = ns * nt;
        for j in 0..slab.nv {
            // Every view of this row of cells, cell after cell.
            let cameras: Vec<Camera> = (0..slab.nu)
                .flat_map(|i| {
                    (0..n * n).map(move |k| {
                        let a = (i as f32 + (k % n) as f32 / n as f32 + 0.5 / n as f32)
                            / slab.nu as f32;
                        let b = (j as f32 + (k / n) as f32 / n as f32 + 0.5 / n as f32)
                            / slab.nv as f32;
                        slab.camera_through(a, b)
                    })
                })
                .collect();
            let (w, h) = (slab.ns * k as u32, slab.nt * k as u32);
            let images = capture_batch(draws, &cameras, lighting, w, h);
            for views in images.chunks(n as usize * n as usize) {
                for p in 0..per_image {
                    let (s, t) = (p % ns, p / ns);
                    let (mut c, mut z, mut seen) = ([0.0f32; 4], 0.0f32, 0u32);
                    for v in views {
                        for q in 0..k * k {
                            let at = (t * k + q / k) * w as usize + s * k + q % k;
                            let x = v.color[at];
                            c = [c[0] + x.r, c[1] + x.g, c[2] + x.b, c[3] + x.a];
                            // The capture cameras look along `forward` from the uv
                            // plane: axial depth is the distance from that plane.
                            if v.depth[at] > 0.0 && v.depth[at].is_finite() {
                                z += v.depth[at];
                                seen += 1;
                            }
                        }
                    }
                    let m = (views.len() * k * k) as f32;
                    samples.push(enc.pack(c[0] / m, c[1] / m, c[2] / m, c[3] / m));
                    depth.push(if seen > 0 {
                        z / seen as f32
                    } else {
                        f32::INFINITY
                    });
                }
            }
            progress((j as usize + 1) * slab.nu as usize, total);
        }
        if slab.is_projective() {
            depth = Vec::new();
        }
        LightField {
            slab,
            rays: Rays::Raw(RawRays::new(samples, depth)),
        }
    }

    /// The light field vector-quantised ([`vq`]); the same light field when it already
    /// is.
    pub fn quantise(&self, settings: &VqSettings) -> Result<(LightField, VqReport), VqError> {
        match &self.rays {
            Rays::Raw(raw) => {
                let (q, report) = Quantised::encode(&self.slab, raw, settings)?;
                Ok((
                    LightField {
                        slab: self.slab,
                        rays: Rays::Quantised(q),
                    },
                    report,
                ))
            }
            Rays::Quantised(_) => Ok((self.clone(), VqReport::default())),
        }
    }

    /// Whether depths are kept (depth correction needs them).
    pub fn has_depth(&self) -> bool {
        match &self.rays {
            Rays::Raw(r) => r.has_depth(),
            Rays::Quantised(q) => !q.depths.is_empty(),
        }
    }

    /// Bytes the samples take in memory (raw, or codebook and indices).
    pub fn bytes(&self) -> usize {
        match &self.rays {
            Rays::Raw(r) => 4 * (r.samples.len() + r.depth.len()),
            Rays::Quantised(q) => q.bytes(),
        }
    }

    /// The depth of sample `(u, v, s, t)` ([`RawRays::depth`]); infinite when not kept.
    #[inline]
    pub fn depth_at(&self, u: u32, v: u32, s: u32, t: u32) -> f32 {
        match &self.rays {
            Rays::Raw(r) => r
                .depth
                .get(r.index(self.slab.counts(), u, v, s, t))
                .copied()
                .unwrap_or(f32::INFINITY),
            Rays::Quantised(q) => q.depth(u, v, s, t),
        }
    }

    /// Sample `(u, v, s, t)` (indices within the slab's counts).
    #[inline]
    pub fn sample(&self, u: u32, v: u32, s: u32, t: u32) -> u32 {
        match &self.rays {
            Rays::Raw(r) => r.samples[r.index(self.slab.counts(), u, v, s, t)],
            Rays::Quantised(q) => q.sample(u, v, s, t),
        }
    }
}
