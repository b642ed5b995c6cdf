//! Small vector helpers: D-dimensional points as x, y, z triples (axis k is x, z in 2D and x, y, z in 3D)
//! and the cross product.

/// A D-dimensional point or vector as x, y, z (y = 0 in 2D).
#[inline(always)]
pub fn to3<T: Copy + Default, const D: usize>(p: [T; D]) -> [T; 3] {
    if D == 2 {
        [p[0], T::default(), p[1]]
    } else {
        [p[0], p[1], p[2]]
    }
}

/// The D-dimensional part of an x, y, z triple.
#[inline(always)]
pub fn from3<T: Copy + Default, const D: usize>(p: [T; 3]) -> [T; D] {
    let mut out = [T::default(); D];
    if D == 2 {
        out[0] = p[0];
        out[1] = p[2];
    } else {
        out.copy_from_slice(&p);
    }
    out
}

/// The cross product a × b.
#[inline(always)]
pub fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
