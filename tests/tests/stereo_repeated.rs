//! Coarse-to-fine matching on a repeated pattern (the `bench stereo` pair whose 16-texel
//! tile repeats about every 43 pixels on the wall, and every 9.5 on the nearer card):
//! matched at full size only, every period is as good a match pixel by pixel and most of
//! the pair is unknown or an alias; drawn toward the half-size match, most is right.

use demos::bench::stereo::repeated_pair;
use ibr::stereo::{luminance, measure, Sgm};

#[test]
fn the_half_size_match_keeps_a_repeated_pattern_off_its_aliases() {
    let (w, h) = (640, 480);
    let pair = &repeated_pair(w, h).pair;
    let (l, r) = (luminance(&pair.left), luminance(&pair.right));
    let bad2 = |sgm: Sgm| {
        let d = sgm.run(&l, &r, w, h).expect("images of the size given");
        measure(&d, &pair.truth, Some(&pair.visible))
            .expect("maps of one size")
            .nonocc
            .bad2
    };
    let fine_only = bad2(Sgm {
        prior: 0,
        min_texture: 0.0,
        ..Sgm::default()
    });
    let coarse_to_fine = bad2(Sgm {
        min_texture: 0.0,
        ..Sgm::default()
    });
    assert!(fine_only > 0.8, "full size only: {fine_only}");
    assert!(coarse_to_fine < 0.3, "coarse to fine: {coarse_to_fine}");
}
