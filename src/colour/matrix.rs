//! Row-major 3×3 matrices of `f64` and the products and inverse the colour conversions use.

/// Row-major 3×3 matrix.
pub type Mat3 = [[f64; 3]; 3];

/// Multiplies a 3×3 matrix by a column vector.
pub fn mat3_mul_vec(m: &Mat3, v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// Matrix product `a · b`.
pub fn mat3_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, o) in row.iter_mut().enumerate() {
            *o = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    out
}

/// Inverse of a 3×3 matrix (adjugate / determinant).
pub fn mat3_inverse(m: &Mat3) -> Mat3 {
    let [[a, b, c], [d, e, f], [g, h, i]] = *m;
    let co00 = e * i - f * h;
    let co01 = -(d * i - f * g);
    let co02 = d * h - e * g;
    let det = a * co00 + b * co01 + c * co02;
    let inv = 1.0 / det;
    [
        [co00 * inv, -(b * i - c * h) * inv, (b * f - c * e) * inv],
        [co01 * inv, (a * i - c * g) * inv, -(a * f - c * d) * inv],
        [co02 * inv, -(a * h - b * g) * inv, (a * e - b * d) * inv],
    ]
}
