//! A piston wave maker: a vertical plate of boundary particles across the tank at its −x end, driven along x
//! by X(t) = (S/2) sin(2πt/T), started with a half-cosine ramp. The liquid fills the tank in front of it; the
//! space behind it stays dry. Linear wave-maker theory (Biesel) gives the waves it makes: H/S =
//! 2 (cosh 2kh − 1) / (sinh 2kh + 2kh). Its settings are [`crate::params::PistonSpec`].

/// The plate's particles (tank frame, x y z; y = 0 in 2D): `layers` behind the face, from the floor to
/// `height`, across `breadth`.
pub fn plate_points(
    face: f64,
    layers: usize,
    height: f64,
    breadth: f64,
    dimension: usize,
    dp: f64,
) -> Vec<[f64; 3]> {
    let nz = ((height / dp).round() as usize).max(1);
    let sz = height / nz as f64;
    let ny = if dimension == 3 {
        ((breadth / dp).round() as usize).max(1)
    } else {
        1
    };
    let sy = breadth / ny as f64;
    let mut out = Vec::with_capacity(layers * nz * ny);
    for l in 0..layers {
        for j in 0..ny {
            for k in 0..nz {
                let y = if dimension == 3 {
                    -0.5 * breadth + (j as f64 + 0.5) * sy
                } else {
                    0.0
                };
                out.push([face - (l as f64 + 0.5) * dp, y, (k as f64 + 0.5) * sz]);
            }
        }
    }
    out
}
