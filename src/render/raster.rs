//! The software rasteriser of shaded triangles: lighting and a depth buffer.

use crate::render::primitives::MeshKind;

/// Light for the shaded surfaces, in camera axes (x right, y up, z towards the viewer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    /// Unit vector towards the key light.
    pub light: [f32; 3],
    /// Light everywhere, as a fraction of the surface colour.
    pub ambient: f32,
    /// Key light's diffuse strength.
    pub diffuse: f32,
    /// Strength of the white highlight.
    pub specular: f32,
}

impl Default for Lighting {
    /// A key light above, left of and in front of the viewer, plus ambient light.
    fn default() -> Self {
        let l = [-0.45f32, 0.6, 0.66];
        let n = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
        Lighting {
            light: [l[0] / n, l[1] / n, l[2] / n],
            ambient: 0.32,
            diffuse: 0.72,
            specular: 0.22,
        }
    }
}

/// One corner of a triangle ready to rasterise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterVertex {
    /// Pixel x, pixel y (down) and depth (smaller is nearer), in the raster's own pixels.
    pub position: [f32; 3],
    /// Unit normal in camera axes (the outward surface normal).
    pub normal: [f32; 3],
    /// Surface colour, 0–1.
    pub colour: [f32; 3],
}

/// A software rasteriser: triangles with barycentric interpolation, a depth buffer and
/// per-pixel two-sided lighting (a triangle seen from behind is lit as its back face, a
/// little darker, so the inside of an open shell reads as inside).
pub struct Rasteriser {
    width: usize,
    height: usize,
    depth: Vec<f32>,
    /// Packed 0xAABBGGRR; alpha 0 where nothing was drawn.
    colour: Vec<u32>,
    /// Whether the nearest opaque thing at each pixel is a body ([`MeshKind::Body`]).
    body: Vec<bool>,
}

/// Opacity of an obstacle where a body lies behind it.
pub const VEIL_ALPHA: f32 = 0.3;

/// Opacity of a half-space's plane seen from inside.
pub const PLANE_ALPHA: f32 = 0.22;

impl Rasteriser {
    /// An empty raster of `width` × `height` pixels.
    pub fn new(width: usize, height: usize) -> Self {
        Rasteriser {
            width,
            height,
            depth: vec![f32::INFINITY; width * height],
            colour: vec![0; width * height],
            body: vec![false; width * height],
        }
    }

    /// Width, pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height, pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Depth at pixel (x, y); infinite where nothing was drawn or outside.
    pub fn depth_at(&self, x: f32, y: f32) -> f32 {
        if x < 0.0 || y < 0.0 {
            return f32::INFINITY;
        }
        let (x, y) = (x as usize, y as usize);
        if x >= self.width || y >= self.height {
            return f32::INFINITY;
        }
        self.depth[y * self.width + x]
    }

    /// Colour at pixel (x, y) as RGBA bytes (alpha 0 where nothing was drawn).
    pub fn rgba_at(&self, x: usize, y: usize) -> [u8; 4] {
        self.colour[y * self.width + x].to_le_bytes()
    }

    /// Draw one opaque triangle of a body: every pixel whose centre is inside and nearer than
    /// what is there.
    pub fn triangle(&mut self, v: &[RasterVertex; 3], light: &Lighting) {
        self.triangle_of(v, light, MeshKind::Body)
    }

    /// Draw one triangle of a mesh of `kind`: every pixel whose centre is inside and nearer
    /// than what is there, opaque or blended over it as `kind` says (see-through parts leave
    /// the depth of what they cover).
    pub fn triangle_of(&mut self, v: &[RasterVertex; 3], light: &Lighting, kind: MeshKind) {
        let [p0, p1, p2] = [v[0].position, v[1].position, v[2].position];
        let area = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1]);
        if area.abs() < 1e-12 || !area.is_finite() {
            return;
        }
        // Counter-clockwise seen from outside appears clockwise on a y-down raster.
        let front = area < 0.0;
        let min_x = p0[0].min(p1[0]).min(p2[0]).floor().max(0.0) as usize;
        let min_y = p0[1].min(p1[1]).min(p2[1]).floor().max(0.0) as usize;
        let max_x = p0[0].max(p1[0]).max(p2[0]).ceil();
        let max_y = p0[1].max(p1[1]).max(p2[1]).ceil();
        if max_x < 0.0 || max_y < 0.0 {
            return;
        }
        let max_x = (max_x as usize).min(self.width);
        let max_y = (max_y as usize).min(self.height);
        if min_x >= max_x || min_y >= max_y {
            return;
        }
        let inv = 1.0 / area;
        // Barycentric weight of vertex k at pixel centre (x, y): e_k(x, y) * inv, with
        // e_k linear: e_k = a_k x + b_k y + c_k.
        let edge = |a: [f32; 3], b: [f32; 3]| {
            let ea = (a[1] - b[1]) * inv;
            let eb = (b[0] - a[0]) * inv;
            let ec = (a[0] * b[1] - a[1] * b[0]) * inv;
            (ea, eb, ec)
        };
        let e0 = edge(p1, p2);
        let e1 = edge(p2, p0);
        let e2 = edge(p0, p1);
        let (z0, z1, z2) = (p0[2], p1[2], p2[2]);
        let sign = if front { 1.0 } else { -1.0 };
        let n = |k: usize| {
            let m = v[k].normal;
            [m[0] * sign, m[1] * sign, m[2] * sign]
        };
        let (n0, n1, n2) = (n(0), n(1), n(2));
        let back_shade = if front { 1.0 } else { 0.78 };
        let (c0, c1, c2) = (v[0].colour, v[1].colour, v[2].colour);
        let l = light.light;
        let h = {
            let h = [l[0], l[1], l[2] + 1.0];
            let k = 1.0 / (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
            [h[0] * k, h[1] * k, h[2] * k]
        };
        const EPS: f32 = -1e-6;
        for y in min_y..max_y {
            let py = y as f32 + 0.5;
            let px0 = min_x as f32 + 0.5;
            let mut w0 = e0.0 * px0 + e0.1 * py + e0.2;
            let mut w1 = e1.0 * px0 + e1.1 * py + e1.2;
            let mut w2 = e2.0 * px0 + e2.1 * py + e2.2;
            let row = y * self.width;
            for x in min_x..max_x {
                if w0 >= EPS && w1 >= EPS && w2 >= EPS {
                    let z = w0 * z0 + w1 * z1 + w2 * z2;
                    let i = row + x;
                    if z < self.depth[i] {
                        let alpha = match kind {
                            MeshKind::Body => 1.0,
                            MeshKind::Obstacle if self.body[i] => VEIL_ALPHA,
                            MeshKind::Obstacle => 1.0,
                            MeshKind::Plane => PLANE_ALPHA,
                        };
                        if alpha >= 1.0 {
                            self.depth[i] = z;
                            self.body[i] = kind == MeshKind::Body;
                        }
                        let mut nx = w0 * n0[0] + w1 * n1[0] + w2 * n2[0];
                        let mut ny = w0 * n0[1] + w1 * n1[1] + w2 * n2[1];
                        let mut nz = w0 * n0[2] + w1 * n1[2] + w2 * n2[2];
                        let len2 = nx * nx + ny * ny + nz * nz;
                        if len2 > 0.0 {
                            let k = 1.0 / len2.sqrt();
                            nx *= k;
                            ny *= k;
                            nz *= k;
                        }
                        let diffuse = (nx * l[0] + ny * l[1] + nz * l[2]).max(0.0);
                        let mut s = (nx * h[0] + ny * h[1] + nz * h[2]).max(0.0);
                        s *= s; // ^2
                        s *= s; // ^4
                        s *= s; // ^8
                        s *= s; // ^16
                        s *= s; // ^32
                        let lit = (light.ambient + light.diffuse * diffuse) * back_shade;
                        let spec = light.specular * s * back_shade;
                        let ch = |k: usize| {
                            let base = w0 * c0[k] + w1 * c1[k] + w2 * c2[k];
                            ((base * lit + spec).clamp(0.0, 1.0) * 255.0 + 0.5) as u32
                        };
                        let mut rgb = [ch(0), ch(1), ch(2)];
                        if alpha < 1.0 {
                            // Over what is there, or over the white background.
                            let under = self.colour[i].to_le_bytes();
                            let white = under[3] == 0;
                            for (k, c) in rgb.iter_mut().enumerate() {
                                let u = if white { 255.0 } else { under[k] as f32 };
                                *c = (alpha * *c as f32 + (1.0 - alpha) * u + 0.5) as u32;
                            }
                        }
                        self.colour[i] = rgb[0] | (rgb[1] << 8) | (rgb[2] << 16) | (255 << 24);
                    }
                }
                w0 += e0.0;
                w1 += e1.0;
                w2 += e2.0;
            }
        }
    }

    /// The raster reduced by `factor` in each direction (box filter), as premultiplied RGBA
    /// bytes whose alpha is the fraction of covered samples.
    pub fn resolve(&self, factor: usize) -> Vec<u8> {
        let factor = factor.max(1);
        let (w, h) = (self.width / factor, self.height / factor);
        let mut out = vec![0u8; w * h * 4];
        let n = (factor * factor) as u32;
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0u32; 4];
                for sy in 0..factor {
                    let row = (y * factor + sy) * self.width + x * factor;
                    for c in &self.colour[row..row + factor] {
                        let b = c.to_le_bytes();
                        if b[3] != 0 {
                            sum[0] += b[0] as u32;
                            sum[1] += b[1] as u32;
                            sum[2] += b[2] as u32;
                            sum[3] += 255;
                        }
                    }
                }
                let o = (y * w + x) * 4;
                for k in 0..4 {
                    out[o + k] = ((sum[k] + n / 2) / n) as u8;
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vertex(x: f32, y: f32, z: f32, normal: [f32; 3]) -> RasterVertex {
        RasterVertex {
            position: [x, y, z],
            normal,
            colour: [0.8, 0.8, 0.8],
        }
    }

    #[test]
    fn nearer_triangle_hides_farther_whatever_the_order() {
        let light = Lighting::default();
        for order in [false, true] {
            let mut r = Rasteriser::new(20, 20);
            let near = [
                vertex(0.0, 0.0, 1.0, [0.0, 0.0, 1.0]),
                vertex(0.0, 20.0, 1.0, [0.0, 0.0, 1.0]),
                vertex(20.0, 0.0, 1.0, [0.0, 0.0, 1.0]),
            ];
            // Far triangle faces away from the light: darker.
            let far = [
                vertex(0.0, 0.0, 2.0, [0.45, -0.6, 0.66]),
                vertex(0.0, 20.0, 2.0, [0.45, -0.6, 0.66]),
                vertex(20.0, 0.0, 2.0, [0.45, -0.6, 0.66]),
            ];
            if order {
                r.triangle(&near, &light);
                r.triangle(&far, &light);
            } else {
                r.triangle(&far, &light);
                r.triangle(&near, &light);
            }
            assert_eq!(r.depth_at(2.5, 2.5), 1.0);
            assert_eq!(r.rgba_at(19, 19)[3], 0, "outside stays empty");
        }
    }

    #[test]
    fn resolve_averages_coverage() {
        let light = Lighting::default();
        let mut r = Rasteriser::new(4, 4);
        // Left half covered.
        let t = |a: [f32; 2], b: [f32; 2], c: [f32; 2]| {
            [
                vertex(a[0], a[1], 0.0, [0.0, 0.0, 1.0]),
                vertex(b[0], b[1], 0.0, [0.0, 0.0, 1.0]),
                vertex(c[0], c[1], 0.0, [0.0, 0.0, 1.0]),
            ]
        };
        r.triangle(&t([0.0, 0.0], [0.0, 4.0], [2.0, 0.0]), &light);
        r.triangle(&t([2.0, 0.0], [0.0, 4.0], [2.0, 4.0]), &light);
        let out = r.resolve(4);
        assert_eq!(out[3], 128);
    }
}
