//! Lane semantics of both backends, checked lane by lane.

use super::*;

#[test]
fn lanes_behave() {
    let a = F8::from_array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
    let b = F8::splat(3.5);
    assert_eq!(a.gt(b).bits(), 0b1111_0000);
    assert_eq!(a.ge(F8::splat(3.0)).bits(), 0b1111_1000);
    assert_eq!(
        a.gt(b).select(a, b).to_array(),
        [3.5, 3.5, 3.5, 3.5, 4.0, 5.0, 6.0, 7.0]
    );
    assert_eq!(I8::lane_range(2, 4).bits(), 0b0001_1100);
    assert_eq!(M8::from_bits(0b1010_0110).bits(), 0b1010_0110);
    assert_eq!(
        (I8::ramp_times(-3) + I8::splat(6)).non_negative().bits(),
        0b0000_0111
    );
    assert_eq!(F8::ramp().to_array()[7], 7.0);
    let c = F8::from_array([-1.0, -0.0, 2.0, f32::NAN, 3.5, -3.5, 0.0, 7.0]);
    assert_eq!(c.abs().to_array()[..3], [1.0, 0.0, 2.0]);
    assert_eq!(c.lt(b).bits(), 0b0110_0111);
    assert_eq!(c.le(b).bits(), 0b0111_0111);
    assert_eq!(c.lt(b).and_not(c.le(F8::splat(0.0))).bits(), 0b0000_0100);
    assert_eq!(c.gt(b).or(c.le(F8::splat(0.0))).bits(), 0b1110_0011);
    assert_eq!(
        F8::ramp().permute([7, 0, 1, 1, 2, 2, 3, 7]).to_array(),
        [7.0, 0.0, 1.0, 1.0, 2.0, 2.0, 3.0, 7.0]
    );
    let hi = F8::ramp() + F8::splat(8.0);
    let (even, odd) = F8::ramp().deinterleave(hi);
    assert_eq!(even.to_array(), [0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0]);
    assert_eq!(odd.to_array(), [1.0, 3.0, 5.0, 7.0, 9.0, 11.0, 13.0, 15.0]);
    let (even, odd) = I8::ramp_times(1).deinterleave(I8::ramp_times(1) + I8::splat(8));
    assert_eq!(even.to_array(), [0, 2, 4, 6, 8, 10, 12, 14]);
    assert_eq!(odd.to_array(), [1, 3, 5, 7, 9, 11, 13, 15]);
    assert_eq!(
        M8::from_bits(0b0101)
            .select_i32(I8::splat(7), I8::splat(-1))
            .to_array()[..4],
        [7, -1, 7, -1]
    );
    assert_eq!(
        I8::ramp_times(2)
            .eq(I8::from_array([0, 2, 5, 6, 0, 0, 12, 14]))
            .bits(),
        0b1100_1011
    );
    let words = [0xff00_0001u32, 2, 3, 4, 5, 6, 7, 8];
    assert_eq!(I8::load_u32(&words).shr::<24>().to_array()[0], 0xff);
    let packed = F8::from_array([0.0, 0.5, 1.0, 2.0, -1.0, f32::NAN, 0.25, 0.75]).clamp01();
    assert_eq!(packed.to_array()[3], 1.0);
    assert_eq!(packed.to_array()[5], 0.0);
    assert_eq!(
        I8::splat(3).shl::<8>().or(I8::splat(1)).to_array()[0],
        0x301
    );
    let table = [10u64 | 20 << 32, 11 | 21 << 32, 12 | 22 << 32];
    let idx = I8::from_array([-5, 0, 1, 2, 3, i32::MAX, i32::MIN, 1]);
    let (lo, hi) = I8::gather_pairs(&table, idx);
    assert_eq!(lo.to_array(), [10, 10, 11, 12, 12, 12, 10, 11]);
    assert_eq!(hi.to_array(), [20, 20, 21, 22, 22, 22, 20, 21]);
    assert_eq!(I8::gather_pairs(&[], idx).0.to_array(), [0; 8]);
    let (lo, hi) = I8::gather_pairs_lanes(&table, idx, M8::from_bits(0b1010_0110));
    assert_eq!(lo.to_array(), [0, 10, 11, 0, 0, 12, 0, 11]);
    assert_eq!(hi.to_array(), [0, 20, 21, 0, 0, 22, 0, 21]);
    let all = I8::gather_pairs_lanes(&table, idx, M8::from_bits(0xff));
    assert_eq!(all.0.to_array(), I8::gather_pairs(&table, idx).0.to_array());
    assert_eq!(
        I8::gather_pairs_lanes(&[], idx, M8::from_bits(1))
            .1
            .to_array(),
        [0; 8]
    );
    let words = [10u32, 11, 12, 13];
    let keep = M8::from_bits(0b1010_0111);
    assert_eq!(
        I8::gather_u32_lanes(&words, idx, keep).to_array(),
        [10, 10, 11, 0, 0, 13, 0, 11]
    );
    assert_eq!(I8::gather_u32_lanes(&[], idx, keep).to_array(), [0; 8]);
    // Quads: indices clamped into 0..=len - 4, each lane's four words in four vectors.
    let words: Vec<u32> = (10..20).collect();
    let quads = I8::load_quads(&words, idx, keep);
    for (k, q) in quads.iter().enumerate() {
        let k = k as i32;
        assert_eq!(
            q.to_array(),
            [10 + k, 10 + k, 11 + k, 0, 0, 16 + k, 0, 11 + k],
            "word {k}"
        );
    }
    let all = I8::load_quads(&words, I8::ramp_times(1), M8::from_bits(0xff));
    assert_eq!(all[3].to_array(), [13, 14, 15, 16, 17, 18, 19, 19]);
    assert_eq!(I8::load_quads(&words[..3], idx, keep)[0].to_array(), [0; 8]);
    // Fused: rounded once, so (1 + e)(1 - e) - 1 keeps the -e^2 an unfused product loses.
    let e = F8::splat(f32::EPSILON);
    let (p, q) = (F8::splat(1.0) + e, F8::splat(1.0) - e);
    assert_eq!(
        p.fma(q, F8::splat(-1.0)).to_array()[0],
        -f32::EPSILON * f32::EPSILON
    );
    assert_eq!(
        p.fnma(q, F8::splat(1.0)).to_array()[0],
        f32::EPSILON * f32::EPSILON
    );
    assert_eq!((p * q + F8::splat(-1.0)).to_array()[0], 0.0);
    let mut s = [0.0; 9];
    a.store(&mut s);
    assert_eq!(F8::load(&s).to_array(), a.to_array());
}

#[test]
fn bits_reinterpret_as_floats() {
    let x = [0.0f32, -0.0, 1.5, -2.25, f32::INFINITY, 1e-40, 3.0e38, 0.1];
    let bits = I8::from_array(x.map(|v| v.to_bits() as i32));
    assert_eq!(
        bits.bits_to_f32().to_array().map(f32::to_bits),
        x.map(f32::to_bits)
    );
}
