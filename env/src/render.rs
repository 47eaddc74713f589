//! The 70x70 renderer of ArmBall / ArmArrow (docs/original-code.md section 2, "Rendering").
//!
//! The original code (UGSL `src/rendering.py`) draws with pygame's `gfxdraw` module, which wraps
//! the SDL_gfx primitives bundled with pygame (`src_c/SDL_gfx/SDL_gfxPrimitives.c`). This module
//! re-implements, in integer / fixed-point arithmetic like the C code, exactly the primitives
//! the original calls, on a 70x70 canvas that starts black and is drawn in opaque white:
//!
//! * ball: `aacircleRGBA` (= `aaellipseColor` with rx = ry = 5), then `filledCircleColor`;
//! * arrow: `aapolygonRGBA` (closed chain of `_aalineColor` without end points, Wu lines),
//!   then `filledPolygonRGBAMT` (16.16 fixed-point scan-line fill).
//!
//! Anti-aliased pixels use the SDL_gfx 32-bit blend `v += ((255 - v) * a) >> 8` with
//! `a = (255 * weight) >> 8` (`pixelColorWeightNolock` -> `_putPixelAlpha`); fully opaque pixels
//! are stored as 255. The image is read like `pygame.surfarray.array2d`, i.e. indexed `[x][y]`,
//! and normalised like the original, `(v - min) / max` in `f32`, so values are exact multiples of
//! 1/255 whenever the image holds a fully white pixel (every non-blank image seen in 40 000
//! random pygame renders of states in [-1, 1]).
//!
//! Geometry (section 2): factors `f = (s + 1) / 2`, pixel `px = int(f_x * 70)`,
//! `py = int(f_y * 70)` (truncation, no y flip, s = 1 maps to the off-canvas pixel 70). The
//! arrow's four vertices are floats (tip at angle `r = 2 pi f_angle`, radius 10; a point at
//! `r + 2pi/3`; the truncated centre `(px, py)`; a point at `r + 4pi/3`) that `gfxdraw` truncates
//! toward zero to integers.
//!
//! The golden test `tests/render_golden.rs` compares this renderer pixel for pixel with images
//! produced by real pygame 2.6.1 (fixture written by `scripts/golden_render.py`): all golden
//! images match exactly, raw and normalised, as did 40 000 random states in a one-off check.
//! pygame 2 differs from the pygame 1.9 of the paper's time in one place that matters here:
//! horizontal outline edges running toward smaller x (see `aa_line_no_endpoint`).
//!
//! Deviations from pygame (none changes a non-blank image):
//! * an image with no lit pixel (a shape entirely off-canvas) is all zeros; the original divides
//!   0 by 0 and returns NaNs. Within [-1, 1] this happens only on the edge s = 1, where the
//!   centre maps to the off-canvas pixel 70 (e.g. an arrow at (1, 0.97) pointing away);
//! * states whose shape cannot touch the canvas (far outside [-1, 1]) or that are not finite
//!   give that blank image; the original would wrap the coordinates to 16 bits instead.

use std::f64::consts::PI;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Image side in pixels (section 2: 70x70, not 50x50).
pub const SIDE: usize = 70;
/// Number of pixels of an image.
pub const PIXELS: usize = SIDE * SIDE;

/// A 70x70 grayscale image, values in \[0,1\], x-major: pixel (x, y) at index x*70 + y.
#[derive(Clone, Debug, PartialEq)]
pub struct Image70(pub Vec<f32>);

impl Image70 {
    /// The value of pixel (x, y) (x-major storage, as `surfarray.array2d` + C-order flatten).
    pub fn get(&self, x: usize, y: usize) -> f32 {
        assert!(
            x < SIDE && y < SIDE,
            "pixel ({x}, {y}) outside the 70x70 image"
        );
        self.0[x * SIDE + y]
    }

    /// The 4900 values, index x*70 + y.
    pub fn as_slice(&self) -> &[f32] {
        &self.0
    }
}

/// Errors of the image writers.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// Creating or writing the file failed.
    #[error("cannot write {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The PNG encoder failed.
    #[error("cannot encode PNG {path}: {source}")]
    Png {
        path: PathBuf,
        #[source]
        source: png::EncodingError,
    },
    /// The image does not hold 4900 values.
    #[error("image for {path} has {len} values, expected {PIXELS}")]
    BadLength { path: PathBuf, len: usize },
}

/// Ball radius in pixels (UGSL `ball_radius`).
const BALL_RADIUS: i32 = 5;
/// Arrow radius in pixels (UGSL `arrow_radius`).
const ARROW_RADIUS: f64 = 10.0;
/// Last pixel index of the canvas (SDL clip rectangle is [0, 69] on both axes).
const LAST: i32 = SIDE as i32 - 1;
/// Pixel coordinates beyond which no shape can touch the canvas (radius 10 + anti-aliasing).
const VISIBLE_MIN: f64 = -16.0;
const VISIBLE_MAX: f64 = SIDE as f64 + 16.0;

/// Render the ball at engineered state (x, y) in \[-1,1\]^2.
pub fn render_ball(x: f64, y: f64) -> Image70 {
    let mut v = vec![0.0f32; PIXELS];
    render_ball_into(x, y, &mut v);
    Image70(v)
}

/// Render the arrow at engineered state (x, y, angle), angle in \[-1,1\] (units of pi, wrapped).
pub fn render_arrow(x: f64, y: f64, angle: f64) -> Image70 {
    let mut v = vec![0.0f32; PIXELS];
    render_arrow_into(x, y, angle, &mut v);
    Image70(v)
}

/// Render the ball into a caller-provided buffer of 4900 f32 (no allocation; used in hot loops).
///
/// Panics if `out.len() != 4900`.
pub fn render_ball_into(x: f64, y: f64, out: &mut [f32]) {
    let mut gray = [0u8; PIXELS];
    let bbox = draw_ball(x, y, &mut gray);
    normalise(&gray, bbox, out);
}

/// The gray level of ArmBalls' distractor in the rendered image (the ball is 1.0): CDGE's
/// grayscale mode sums the RGB channels, ball (1, 1, 0) and distractor (0, 0, 1).
pub const DISTRACTOR_GRAY: f32 = 0.5;

/// Render ArmBalls' two balls (`env::armballs`) into a caller-provided buffer of 4900 f32: the
/// controllable ball at (x, y) white (1.0) and the distractor at (dx, dy) gray
/// ([`DISTRACTOR_GRAY`], 0.5), drawn on top of it. Each ball is the ArmBall
/// image of its position (same radius, same anti-aliasing, each normalised alone); the
/// distractor's image is its coverage `a` in [0, 1], composited as `ball (1 - a) + 0.5 a`.
/// Unlike the follow-up's gizeh renderer (RGB, 64x64, radii 5.44 / 4.8 px, per-image
/// normalisation), both balls keep the ArmBall look: `docs/armballs.md`.
///
/// Panics if `out.len() != 4900`.
pub fn render_balls_into(x: f64, y: f64, dx: f64, dy: f64, out: &mut [f32]) {
    let mut distractor = [0f32; PIXELS];
    render_ball_into(x, y, out);
    render_ball_into(dx, dy, &mut distractor);
    let gray = DISTRACTOR_GRAY;
    for (o, a) in out.iter_mut().zip(distractor) {
        *o = *o * (1.0 - a) + gray * a;
    }
}

/// Render the arrow into a caller-provided buffer of 4900 f32 (no allocation; used in hot loops).
///
/// Panics if `out.len() != 4900`.
pub fn render_arrow_into(x: f64, y: f64, angle: f64, out: &mut [f32]) {
    let mut gray = [0u8; PIXELS];
    let bbox = draw_arrow(x, y, angle, &mut gray);
    normalise(&gray, bbox, out);
}

/// The raw gray levels (0..=255, before normalisation) of the ball image, x-major, as
/// `surfarray.array2d` would give them (one channel of the white-on-black RGB value).
///
/// Panics if `gray.len() != 4900`.
pub fn render_ball_gray(x: f64, y: f64, gray: &mut [u8]) {
    let gray: &mut [u8; PIXELS] = gray.try_into().expect("gray buffer must hold 4900 pixels");
    gray.fill(0);
    draw_ball(x, y, gray);
}

/// The raw gray levels (0..=255, before normalisation) of the arrow image, x-major.
///
/// Panics if `gray.len() != 4900`.
pub fn render_arrow_gray(x: f64, y: f64, angle: f64, gray: &mut [u8]) {
    let gray: &mut [u8; PIXELS] = gray.try_into().expect("gray buffer must hold 4900 pixels");
    gray.fill(0);
    draw_arrow(x, y, angle, gray);
}

/// The integer pixel centre `(int(f_x * 70), int(f_y * 70))` of engineered state (x, y), or
/// `None` when it is not finite or so far off-canvas that nothing can be drawn.
fn pixel_centre(x: f64, y: f64) -> Option<(f64, f64)> {
    let px = ((x + 1.0) / 2.0 * SIDE as f64).trunc();
    let py = ((y + 1.0) / 2.0 * SIDE as f64).trunc();
    let visible = |p: f64| (VISIBLE_MIN..=VISIBLE_MAX).contains(&p);
    (visible(px) && visible(py)).then_some((px, py))
}

/// The four integer vertices (tip, left, centre, right) that `gfxdraw.aapolygon` /
/// `filled_polygon` receive for the arrow at engineered state (x, y, angle): the float points
/// of UGSL `ArmArrowRenderer._render`, truncated toward zero (`Sint16FromObj`).
/// `None` when the state is not finite or the arrow cannot touch the canvas.
pub fn arrow_vertices(x: f64, y: f64, angle: f64) -> Option<[(i32, i32); 4]> {
    let (px, py) = pixel_centre(x, y)?;
    let fa = (angle + 1.0) / 2.0;
    if !fa.is_finite() {
        return None;
    }
    // Same float operations, in the same order, as the original (numpy float64 = IEEE f64,
    // numpy's cos/sin = glibc's, which Rust's f64::cos/sin also call on Linux).
    let r = fa * 2.0 * PI;
    let r2 = r + 2.0 * PI / 3.0;
    let r4 = r + 4.0 * PI / 3.0;
    let pt = |a: f64| {
        let fx = libm::cos(a) * ARROW_RADIUS + px;
        let fy = libm::sin(a) * ARROW_RADIUS + py;
        (fx.trunc() as i32, fy.trunc() as i32)
    };
    Some([pt(r), pt(r2), (px as i32, py as i32), pt(r4)])
}

/// Draw the ball (white) on a black canvas; returns the dirty bounding box.
fn draw_ball(x: f64, y: f64, gray: &mut [u8; PIXELS]) -> BBox {
    let mut canvas = Canvas::new(gray);
    if let Some((px, py)) = pixel_centre(x, y) {
        let (cx, cy) = (px as i32, py as i32);
        // gfxdraw.aacircle, then gfxdraw.filled_circle (UGSL ArmBallRenderer._render).
        aa_ellipse(&mut canvas, cx, cy, BALL_RADIUS, BALL_RADIUS);
        filled_circle(&mut canvas, cx, cy, BALL_RADIUS);
    }
    canvas.bbox
}

/// Draw the arrow (white) on a black canvas; returns the dirty bounding box.
fn draw_arrow(x: f64, y: f64, angle: f64, gray: &mut [u8; PIXELS]) -> BBox {
    let mut canvas = Canvas::new(gray);
    if let Some(v) = arrow_vertices(x, y, angle) {
        let vx = v.map(|p| p.0);
        let vy = v.map(|p| p.1);
        // gfxdraw.aapolygon, then gfxdraw.filled_polygon (UGSL ArmArrowRenderer._render).
        aa_polygon(&mut canvas, &vx, &vy);
        filled_polygon(&mut canvas, &vx, &vy);
    }
    canvas.bbox
}

/// `(v - min) / max` in f32 over the whole image, as the original does after `array2d`
/// (the raw values are gray * 0x010101; the factor cancels exactly in f32 since every raw value
/// is below 2^24). Pixels outside `bbox` are 0.
fn normalise(gray: &[u8; PIXELS], bbox: BBox, out: &mut [f32]) {
    assert_eq!(out.len(), PIXELS, "output buffer must hold 4900 pixels");
    out.fill(0.0);
    if bbox.is_empty() {
        return; // all black: the original gives NaN (0 / 0); we keep zeros
    }
    let full = bbox.x0 == 0 && bbox.y0 == 0 && bbox.x1 == LAST && bbox.y1 == LAST;
    let (mut lo, mut hi) = (if full { u8::MAX } else { 0 }, 0u8);
    for x in bbox.x0..=bbox.x1 {
        let row =
            &gray[x as usize * SIDE + bbox.y0 as usize..=x as usize * SIDE + bbox.y1 as usize];
        for &v in row {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    let range = hi - lo;
    if range == 0 {
        return; // uniform image: 0 / 0 in the original
    }
    let range = f32::from(range);
    if lo != 0 {
        // Only possible if every pixel is lit (never for these shapes): shift everything.
        for (o, &v) in out.iter_mut().zip(gray.iter()) {
            *o = f32::from(v - lo) / range;
        }
        return;
    }
    for x in bbox.x0..=bbox.x1 {
        let start = x as usize * SIDE;
        let (y0, y1) = (bbox.y0 as usize, bbox.y1 as usize);
        for (o, &v) in out[start + y0..=start + y1]
            .iter_mut()
            .zip(&gray[start + y0..=start + y1])
        {
            *o = f32::from(v) / range;
        }
    }
}

// ------------------------------------------------------------------------------------------
// Canvas and SDL_gfx primitives (re-implemented; the names refer to SDL_gfxPrimitives.c).
// ------------------------------------------------------------------------------------------

/// Inclusive bounding box of the pixels written (empty when x0 > x1).
#[derive(Clone, Copy, Debug)]
struct BBox {
    x0: i32,
    x1: i32,
    y0: i32,
    y1: i32,
}

impl BBox {
    const EMPTY: BBox = BBox {
        x0: i32::MAX,
        x1: i32::MIN,
        y0: i32::MAX,
        y1: i32::MIN,
    };

    fn is_empty(&self) -> bool {
        self.x0 > self.x1
    }
}

/// A 70x70 white-on-black canvas of gray levels, x-major, with the SDL clip rectangle
/// [0, 69]^2 applied at pixel level (as `fastPixelColorNolock` / `_putPixelAlpha` do).
struct Canvas<'a> {
    px: &'a mut [u8; PIXELS],
    bbox: BBox,
}

impl<'a> Canvas<'a> {
    fn new(px: &'a mut [u8; PIXELS]) -> Self {
        Canvas {
            px,
            bbox: BBox::EMPTY,
        }
    }

    #[inline]
    fn index(&mut self, x: i32, y: i32) -> Option<usize> {
        if (0..=LAST).contains(&x) && (0..=LAST).contains(&y) {
            let b = &mut self.bbox;
            b.x0 = b.x0.min(x);
            b.x1 = b.x1.max(x);
            b.y0 = b.y0.min(y);
            b.y1 = b.y1.max(y);
            Some(x as usize * SIDE + y as usize)
        } else {
            None
        }
    }

    /// `pixelColorNolock` with opaque white: store 255.
    #[inline]
    fn put(&mut self, x: i32, y: i32) {
        if let Some(i) = self.index(x, y) {
            self.px[i] = 255;
        }
    }

    /// `_putPixelAlpha` (32 bpp, DEFAULT_ALPHA_PIXEL_ROUTINE) of white with blend factor
    /// `alpha`: `v + (((255 - v) * alpha) >> 8)`, or a plain store when alpha is 255.
    #[inline]
    fn blend(&mut self, x: i32, y: i32, alpha: u32) {
        if let Some(i) = self.index(x, y) {
            if alpha == 255 {
                self.px[i] = 255;
            } else {
                let v = u32::from(self.px[i]);
                self.px[i] = (v + (((255 - v) * alpha) >> 8)) as u8;
            }
        }
    }

    /// `pixelColorWeightNolock`: the colour alpha (255) is scaled by `weight` as
    /// `(255 * weight) >> 8`, then blended.
    #[inline]
    fn weight(&mut self, x: i32, y: i32, weight: u32) {
        self.blend(x, y, (255 * weight) >> 8);
    }

    /// `hlineColor` with opaque white: pixels (x1..=x2, y), ends swapped if needed, clipped.
    fn hline(&mut self, x1: i32, x2: i32, y: i32) {
        let (a, b) = if x1 > x2 { (x2, x1) } else { (x1, x2) };
        if b < 0 || a > LAST || !(0..=LAST).contains(&y) {
            return;
        }
        for x in a.max(0)..=b.min(LAST) {
            self.put(x, y);
        }
    }

    /// `vlineColor` with opaque white: pixels (x, y1..=y2), ends swapped if needed, clipped.
    fn vline(&mut self, x: i32, y1: i32, y2: i32) {
        let (a, b) = if y1 > y2 { (y2, y1) } else { (y1, y2) };
        if !(0..=LAST).contains(&x) || b < 0 || a > LAST {
            return;
        }
        for y in a.max(0)..=b.min(LAST) {
            self.put(x, y);
        }
    }
}

/// True when the box [x - rx, x + rx] x [y - ry, y + ry] misses the canvas (the early exit of
/// the circle / ellipse primitives).
fn box_invisible(x: i32, y: i32, rx: i32, ry: i32) -> bool {
    x + rx < 0 || x - rx > LAST || y + ry < 0 || y - ry > LAST
}

/// `aaellipseColor` (pygame's bundled SDL_gfx; `aacircleRGBA` calls it with rx = ry): the
/// midpoint ellipse of Lindstroem / sge, drawing each step's pixel pair with weights
/// `255 - w` and `w`, `w = (u8)(255 * |d| / |s|)` (in f32), and the four "end points" opaque.
fn aa_ellipse(c: &mut Canvas, x: i32, y: i32, rx: i32, ry: i32) {
    debug_assert!(rx > 0 && ry > 0);
    if box_invisible(x, y, rx, ry) {
        return;
    }
    let a2 = rx * rx;
    let b2 = ry * ry;
    let ds = 2 * a2;
    let dt = 2 * b2;
    let xc2 = 2 * x;
    let yc2 = 2 * y;
    let sab = f64::from(a2 + b2).sqrt();
    // lrint: round to nearest, ties to even (default rounding mode).
    let dxt = (f64::from(a2) / sab).round_ties_even() as i32;
    let mut t = 0i32;
    let mut s = -2 * a2 * ry;
    let mut d = 0i32;
    let mut xp = x;
    let mut yp = y - ry;

    // "End points"
    c.put(xp, yp);
    c.put(xc2 - xp, yp);
    c.put(xp, yc2 - yp);
    c.put(xc2 - xp, yc2 - yp);

    let weights = |num: i32, den: i32| -> (u32, u32) {
        let cp = if den != 0 {
            (num.abs() as f32 / den.abs() as f32).min(1.0)
        } else {
            1.0
        };
        let w = u32::from((cp * 255.0) as u8);
        (w, 255 - w)
    };

    for _ in 1..=dxt {
        xp -= 1;
        d += t - b2;
        let ys;
        if d >= 0 {
            ys = yp - 1;
        } else if (d - s - a2) > 0 {
            if (2 * d - s - a2) >= 0 {
                ys = yp + 1;
            } else {
                ys = yp;
                yp += 1;
                d -= s + a2;
                s += ds;
            }
        } else {
            yp += 1;
            ys = yp + 1;
            d -= s + a2;
            s += ds;
        }
        t -= dt;
        let (w, iw) = weights(d, s);
        // Upper half
        let xx = xc2 - xp;
        c.weight(xp, yp, iw);
        c.weight(xx, yp, iw);
        c.weight(xp, ys, w);
        c.weight(xx, ys, w);
        // Lower half
        let yy = yc2 - yp;
        c.weight(xp, yy, iw);
        c.weight(xx, yy, iw);
        let yy = yc2 - ys;
        c.weight(xp, yy, w);
        c.weight(xx, yy, w);
    }

    let dyt = (f64::from(b2) / sab).round_ties_even() as i32;
    for _ in 1..=dyt {
        yp += 1;
        d -= s + a2;
        let xs;
        if d <= 0 {
            xs = xp + 1;
        } else if (d + t - b2) < 0 {
            if (2 * d + t - b2) <= 0 {
                xs = xp - 1;
            } else {
                xs = xp;
                xp -= 1;
                d += t - b2;
                t -= dt;
            }
        } else {
            xp -= 1;
            xs = xp - 1;
            d += t - b2;
            t -= dt;
        }
        s += ds;
        let (w, iw) = weights(d, t);
        // Left half
        let xx = xc2 - xp;
        let yy = yc2 - yp;
        c.weight(xp, yp, iw);
        c.weight(xx, yp, iw);
        c.weight(xp, yy, iw);
        c.weight(xx, yy, iw);
        // Right half
        let xx = xc2 - xs;
        c.weight(xs, yp, w);
        c.weight(xx, yp, w);
        c.weight(xs, yy, w);
        c.weight(xx, yy, w);
    }
}

/// `filledCircleColor`: midpoint circle (sge / Schiffler) filled with horizontal spans,
/// each span drawn once (`ocx` / `ocy` bookkeeping).
fn filled_circle(c: &mut Canvas, x: i32, y: i32, rad: i32) {
    debug_assert!(rad > 0);
    if box_invisible(x, y, rad, rad) {
        return;
    }
    let (mut cx, mut cy) = (0i32, rad);
    let (mut ocx, mut ocy) = (-1i32, -1i32); // (Sint16) 0xffff
    let mut df = 1 - rad;
    let mut d_e = 3;
    let mut d_se = -2 * rad + 5;
    loop {
        let (xpcx, xmcx, xpcy, xmcy) = (x + cx, x - cx, x + cy, x - cy);
        if ocy != cy {
            if cy > 0 {
                c.hline(xmcx, xpcx, y + cy);
                c.hline(xmcx, xpcx, y - cy);
            } else {
                c.hline(xmcx, xpcx, y);
            }
            ocy = cy;
        }
        if ocx != cx {
            if cx != cy {
                if cx > 0 {
                    c.hline(xmcy, xpcy, y - cx);
                    c.hline(xmcy, xpcy, y + cx);
                } else {
                    c.hline(xmcy, xpcy, y);
                }
            }
            ocx = cx;
        }
        if df < 0 {
            df += d_e;
            d_e += 2;
            d_se += 2;
        } else {
            df += d_se;
            d_e += 2;
            d_se += 4;
            cy -= 1;
        }
        cx += 1;
        if cx > cy {
            break;
        }
    }
}

/// `aapolygonColor`: the closed chain of `_aalineColor(..., draw_endpoint = 0)`.
fn aa_polygon(c: &mut Canvas, vx: &[i32; 4], vy: &[i32; 4]) {
    for i in 1..4 {
        aa_line_no_endpoint(c, vx[i - 1], vy[i - 1], vx[i], vy[i]);
    }
    aa_line_no_endpoint(c, vx[3], vy[3], vx[0], vy[0]);
}

const CLIP_LEFT: u8 = 0x1;
const CLIP_RIGHT: u8 = 0x2;
const CLIP_BOTTOM: u8 = 0x4;
const CLIP_TOP: u8 = 0x8;

/// `_clipEncode` against the canvas [0, 69]^2.
fn clip_encode(x: i32, y: i32) -> u8 {
    let mut code = 0;
    if x < 0 {
        code |= CLIP_LEFT;
    } else if x > LAST {
        code |= CLIP_RIGHT;
    }
    if y < 0 {
        code |= CLIP_TOP;
    } else if y > LAST {
        code |= CLIP_BOTTOM;
    }
    code
}

/// `_clipLine`: Cohen-Sutherland with an `f32` slope and truncating casts, moving (and possibly
/// swapping) the end points in place. Returns whether anything is left to draw.
fn clip_line(x1: &mut i32, y1: &mut i32, x2: &mut i32, y2: &mut i32) -> bool {
    // The C loop has no bound; it ends after a few rounds for every line we draw. The bound
    // only guards against an endless loop.
    for _ in 0..64 {
        let mut code1 = clip_encode(*x1, *y1);
        let mut code2 = clip_encode(*x2, *y2);
        if code1 | code2 == 0 {
            return true;
        }
        if code1 & code2 != 0 {
            return false;
        }
        if code1 == 0 {
            std::mem::swap(x1, x2);
            std::mem::swap(y1, y2);
            std::mem::swap(&mut code1, &mut code2);
        }
        let m: f32 = if *x2 != *x1 {
            (*y2 - *y1) as f32 / (*x2 - *x1) as f32
        } else {
            1.0
        };
        if code1 & CLIP_LEFT != 0 {
            *y1 += ((0 - *x1) as f32 * m) as i32;
            *x1 = 0;
        } else if code1 & CLIP_RIGHT != 0 {
            *y1 += ((LAST - *x1) as f32 * m) as i32;
            *x1 = LAST;
        } else if code1 & CLIP_BOTTOM != 0 {
            if *x2 != *x1 {
                *x1 += ((LAST - *y1) as f32 / m) as i32;
            }
            *y1 = LAST;
        } else if code1 & CLIP_TOP != 0 {
            if *x2 != *x1 {
                *x1 += ((0 - *y1) as f32 / m) as i32;
            }
            *y1 = 0;
        }
    }
    false
}

/// `_aalineColor` with `draw_endpoint = 0`: Wu's anti-aliased line (Abrash / Schiffler, 32-bit
/// fixed-point error accumulator, 8 intensity bits), after clipping. Quirks kept: the first
/// pixel is drawn opaque at the (clipped, possibly swapped) first point, the last one is not
/// drawn (except on vertical and horizontal lines, drawn whole as opaque spans); a 45-degree
/// line has a zero step (the 16.16 shift overflows) and is drawn at weight 255 on the main pixel.
///
/// Version note: pygame 2 (checked against 2.6.1) draws a horizontal line whole whatever its
/// direction (`if (dx != 0) hlineColor(xx0, xx0 + dx)`, the fix of pygame issue #622). The
/// SDL_gfx of the pygame 1.9 era tested `dx > 0` instead and drew only the first pixel of a
/// horizontal edge running toward smaller x; with the authors' pygame (2017) such an arrow
/// edge would be missing from the outline (the fill does not cover it: horizontal edges are
/// skipped and the scan-line spans are half-open). This module follows pygame 2.
fn aa_line_no_endpoint(c: &mut Canvas, x1: i32, y1: i32, x2: i32, y2: i32) {
    let (mut x1, mut y1, mut x2, mut y2) = (x1, y1, x2, y2);
    if !clip_line(&mut x1, &mut y1, &mut x2, &mut y2) {
        return;
    }
    let (mut xx0, mut yy0, mut xx1, mut yy1) = (x1, y1, x2, y2);
    if yy0 > yy1 {
        std::mem::swap(&mut yy0, &mut yy1);
        std::mem::swap(&mut xx0, &mut xx1);
    }
    let mut dx = xx1 - xx0;
    let mut dy = yy1 - yy0;

    if dx == 0 {
        // Vertical line
        if dy > 0 {
            c.vline(x1, yy0, yy0 + dy);
        } else {
            c.put(x1, y1);
        }
        return;
    }
    if dy == 0 {
        // Horizontal line: the whole span, in either direction (pygame 2, see the doc comment;
        // dx == 0 was handled above).
        c.hline(xx0, xx0 + dx, y1);
        return;
    }

    let xdir = if dx >= 0 {
        1
    } else {
        dx = -dx;
        -1
    };
    let mut erracc: u32 = 0;
    const INTSHIFT: u32 = 32 - 8;

    // Initial pixel in the foreground colour.
    c.put(x1, y1);

    if dy > dx {
        // y-major: 16-bit fraction of a pixel that x advances per y step, shifted to the top.
        let erradj: u32 = (((dx << 16) / dy) as u32) << 16;
        let mut x0pxdir = xx0 + xdir;
        loop {
            dy -= 1;
            if dy == 0 {
                break;
            }
            let erracctmp = erracc;
            erracc = erracc.wrapping_add(erradj);
            if erracc <= erracctmp {
                // rollover: x advances
                xx0 = x0pxdir;
                x0pxdir += xdir;
            }
            yy0 += 1;
            let wgt = (erracc >> INTSHIFT) & 255;
            c.weight(xx0, yy0, 255 - wgt);
            c.weight(x0pxdir, yy0, wgt);
        }
    } else {
        // x-major. For dx == dy the quotient is 65536 and the shift overflows to 0 (the C code
        // computes it in 32-bit int).
        let erradj: u32 = (((dy << 16) / dx) as u32).wrapping_shl(16);
        let mut y0p1 = yy0 + 1;
        loop {
            dx -= 1;
            if dx == 0 {
                break;
            }
            let erracctmp = erracc;
            erracc = erracc.wrapping_add(erradj);
            if erracc <= erracctmp {
                // rollover: y advances
                yy0 = y0p1;
                y0p1 += 1;
            }
            xx0 += xdir;
            let wgt = (erracc >> INTSHIFT) & 255;
            c.weight(xx0, yy0, 255 - wgt);
            c.weight(xx0, y0p1, wgt);
        }
    }
}

/// `filledPolygonColorMT`: scan lines from min y to max y; each non-horizontal edge is
/// intersected in 16.16 fixed point on the half-open span [y1, y2) (plus y2 on the last scan
/// line), the intersections are sorted and filled in pairs with spans rounded inward
/// (`xa = round(ints[i] + 1)`, `xb = round(ints[i + 1] - 1)`, `hlineColor` swapping reversed
/// ends).
fn filled_polygon(c: &mut Canvas, vx: &[i32; 4], vy: &[i32; 4]) {
    const N: usize = 4;
    let mut miny = vy[0];
    let mut maxy = vy[0];
    for &v in &vy[1..] {
        if v < miny {
            miny = v;
        } else if v > maxy {
            maxy = v;
        }
    }
    // Scan lines outside the canvas draw nothing (hlineColor clips them away).
    for y in miny.max(0)..=maxy.min(LAST) {
        let mut ints = [0i32; N];
        let mut count = 0;
        for i in 0..N {
            let (ind1, ind2) = if i == 0 { (N - 1, 0) } else { (i - 1, i) };
            let (ya, yb) = (vy[ind1], vy[ind2]);
            let (y1, y2, x1, x2) = if ya < yb {
                (ya, yb, vx[ind1], vx[ind2])
            } else if ya > yb {
                (yb, ya, vx[ind2], vx[ind1])
            } else {
                continue;
            };
            if (y >= y1 && y < y2) || (y == maxy && y > y1 && y <= y2) {
                ints[count] = ((65536 * (y - y1)) / (y2 - y1)) * (x2 - x1) + 65536 * x1;
                count += 1;
            }
        }
        let ints = &mut ints[..count];
        ints.sort_unstable();
        for pair in ints.chunks_exact(2) {
            let xa = pair[0] + 1;
            let xa = (xa >> 16) + ((xa & 32768) >> 15);
            let xb = pair[1] - 1;
            let xb = (xb >> 16) + ((xb & 32768) >> 15);
            c.hline(xa, xb, y);
        }
    }
}

// ------------------------------------------------------------------------------------------
// Writers
// ------------------------------------------------------------------------------------------

fn check_len(img: &Image70, path: &Path) -> Result<(), RenderError> {
    if img.0.len() != PIXELS {
        return Err(RenderError::BadLength {
            path: path.to_path_buf(),
            len: img.0.len(),
        });
    }
    Ok(())
}

/// Write as .npy: float32, shape (70, 70), C order, indexed `[x][y]` (what the original's
/// `array2d`-based images look like to numpy).
pub fn write_npy(img: &Image70, path: &Path) -> Result<(), RenderError> {
    check_len(img, path)?;
    crate::npy::write_npy_f32_file(path, SIDE, SIDE, &img.0).map_err(|source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Upscaling factor of [`write_png`].
const PNG_SCALE: usize = 4;

/// Write a PNG a person can look at: 8-bit grayscale, 4x nearest-neighbour upscaling, oriented
/// like the world (x to the right, larger y higher in the picture, i.e. rows flipped; the
/// original's array2d image has no y flip, so it shows the world upside down when plotted
/// as a matrix).
pub fn write_png(img: &Image70, path: &Path) -> Result<(), RenderError> {
    check_len(img, path)?;
    write_png_grid(&[&img.0[..]], 1, PNG_SCALE, path)
}

/// Gap between the cells of [`write_png_grid`], in output pixels (mid gray).
pub(crate) const GRID_GAP: usize = 2;

/// Write 70x70 images (`PIXELS` values in [0, 1] each, indexed `[x][y]`) as one grayscale PNG:
/// `cols` per row, each upscaled `scale` times and oriented like [`write_png`], separated by a
/// gray gap. For figures (reconstructions: inputs above outputs).
pub fn write_png_grid(
    images: &[&[f32]],
    cols: usize,
    scale: usize,
    path: &Path,
) -> Result<(), RenderError> {
    let io_err = |source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    };
    if images.is_empty() || cols == 0 || scale == 0 || images.iter().any(|i| i.len() != PIXELS) {
        return Err(io_err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("a PNG grid needs images of {PIXELS} pixels, columns and a scale"),
        )));
    }
    let (width, height, data) = grid_bytes(images.len(), cols, scale, SIDE, 1, |k, x, y, _| {
        images[k][x * SIDE + y]
    });
    write_png_bytes(path, width, height, png::ColorType::Grayscale, &data)
}

/// The 8-bit pixels of a grid of `n` square pictures of `side` x `side` pixels and `channels`
/// values each, `cols` per row, each upscaled `scale` times, separated by a mid-gray gap of
/// [`GRID_GAP`] pixels, with rows flipped so that larger y is higher (as in the world); `value(k,
/// x, y, c)` is channel `c` of picture `k` at (x, y), in [0, 1]. Returns (width, height, bytes).
pub(crate) fn grid_bytes(
    n: usize,
    cols: usize,
    scale: usize,
    side: usize,
    channels: usize,
    value: impl Fn(usize, usize, usize, usize) -> f32,
) -> (usize, usize, Vec<u8>) {
    let rows = n.div_ceil(cols);
    let cell = side * scale;
    let (width, height) = (
        cols * cell + (cols - 1) * GRID_GAP,
        rows * cell + (rows - 1) * GRID_GAP,
    );
    let mut data = vec![128u8; width * height * channels];
    for k in 0..n {
        let (r0, c0) = (
            (k / cols) * (cell + GRID_GAP),
            (k % cols) * (cell + GRID_GAP),
        );
        for row in 0..cell {
            let y = side - 1 - row / scale;
            let start = ((r0 + row) * width + c0) * channels;
            let line = &mut data[start..start + cell * channels];
            for (col, px) in line.chunks_exact_mut(channels).enumerate() {
                for (c, p) in px.iter_mut().enumerate() {
                    *p = (value(k, col / scale, y, c).clamp(0.0, 1.0) * 255.0).round() as u8;
                }
            }
        }
    }
    (width, height, data)
}

/// Encode 8-bit `data` (`height` rows of `width` pixels of `color`) as a PNG file.
pub(crate) fn write_png_bytes(
    path: &Path,
    width: usize,
    height: usize,
    color: png::ColorType,
    data: &[u8],
) -> Result<(), RenderError> {
    let io_err = |source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    };
    let png_err = |source| RenderError::Png {
        path: path.to_path_buf(),
        source,
    };
    let file = File::create(path).map_err(io_err)?;
    let mut buf = BufWriter::new(file);
    {
        let mut encoder = png::Encoder::new(&mut buf, width as u32, height as u32);
        encoder.set_color(color);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(png_err)?;
        writer.write_image_data(data).map_err(png_err)?;
        writer.finish().map_err(png_err)?;
    }
    buf.flush().map_err(io_err)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gray_ball(x: f64, y: f64) -> Vec<u8> {
        let mut g = vec![0u8; PIXELS];
        render_ball_gray(x, y, &mut g);
        g
    }

    fn gray_arrow(x: f64, y: f64, a: f64) -> Vec<u8> {
        let mut g = vec![0u8; PIXELS];
        render_arrow_gray(x, y, a, &mut g);
        g
    }

    /// Engineered coordinate whose pixel is `p`: f = (p + 0.5) / 70.
    fn s_of(p: usize) -> f64 {
        2.0 * (p as f64 + 0.5) / SIDE as f64 - 1.0
    }

    #[test]
    fn ball_footprint_counts() {
        // docs/original-code.md section 2: 11x11 footprint, 97 non-zero pixels, 89 at 1.0, 8 at
        // 151/255 or 228/255.
        for (x, y) in [(0.0, 0.0), (0.6, 0.6), (-0.5, 0.3)] {
            let img = render_ball(x, y);
            let v = img.as_slice();
            let nz: Vec<f32> = v.iter().copied().filter(|&p| p > 0.0).collect();
            assert_eq!(nz.len(), 97, "state ({x}, {y})");
            assert_eq!(nz.iter().filter(|&&p| p == 1.0).count(), 89);
            let aa: Vec<f32> = nz.iter().copied().filter(|&p| p < 1.0).collect();
            assert_eq!(aa.len(), 8);
            for p in aa {
                assert!(p == 151.0 / 255.0 || p == 228.0 / 255.0, "AA value {p}");
            }
            // 11x11 footprint around the centre.
            let (cx, cy) = (
                ((x + 1.0) / 2.0 * 70.0) as usize,
                ((y + 1.0) / 2.0 * 70.0) as usize,
            );
            for i in 0..SIDE {
                for j in 0..SIDE {
                    if img.get(i, j) > 0.0 {
                        assert!(i.abs_diff(cx) <= 5 && j.abs_diff(cy) <= 5);
                    }
                }
            }
            assert!(img.get(cx - 5, cy) > 0.0 && img.get(cx + 5, cy) > 0.0);
            assert!(img.get(cx, cy - 5) > 0.0 && img.get(cx, cy + 5) > 0.0);
        }
    }

    #[test]
    fn ball_centre_pixel_is_truncated() {
        // s = 0 -> f = 0.5 -> pixel 35; s = 0.6 -> f = 0.8 -> 56.00000000000001 -> 56.
        let g = gray_ball(0.0, 0.6);
        assert_eq!(g[35 * SIDE + 56], 255);
        assert_eq!(g[(35 - 5) * SIDE + 56], 255);
        assert_eq!(g[(35 - 6) * SIDE + 56], 0);
        assert_eq!(g[35 * SIDE + 56 + 5], 255);
        assert_eq!(g[35 * SIDE + 56 + 6], 0);
    }

    #[test]
    fn x_major_indexing() {
        // A ball at high x lights pixels with high index / 70; at high y, high index % 70.
        let img = render_ball(0.8, -0.8);
        for (i, &v) in img.as_slice().iter().enumerate() {
            if v > 0.0 {
                assert!(i / SIDE >= 57, "x = {}", i / SIDE);
                assert!(i % SIDE <= 12, "y = {}", i % SIDE);
            }
        }
        let px = s_of(60);
        let img = render_ball(px, s_of(10));
        assert_eq!(img.get(60, 10), 1.0);
        assert_eq!(img.as_slice()[60 * SIDE + 10], 1.0);
    }

    #[test]
    fn values_in_unit_interval_and_multiples_of_1_255() {
        let mut out = vec![0.0f32; PIXELS];
        for k in 0..200 {
            let t = k as f64 / 199.0;
            let (x, y, a) = (2.0 * t - 1.0, (7.3 * t).sin(), (13.1 * t).cos());
            for arrow in [false, true] {
                if arrow {
                    render_arrow_into(x, y, a, &mut out);
                } else {
                    render_ball_into(x, y, &mut out);
                }
                let max = out.iter().copied().fold(0.0f32, f32::max);
                assert_eq!(max, 1.0, "state ({x}, {y}, {a}) arrow={arrow}");
                for &v in &out {
                    assert!((0.0..=1.0).contains(&v));
                    let q = v * 255.0;
                    assert!(
                        (q - q.round()).abs() < 1e-4,
                        "{v} is not a multiple of 1/255"
                    );
                }
            }
        }
    }

    #[test]
    fn clipping_at_edges_and_far_away() {
        // s = 1 maps to pixel 70 (off-canvas): only the lower-left quarter is drawn.
        let g = gray_ball(1.0, 1.0);
        let lit: Vec<(usize, usize)> = (0..PIXELS)
            .filter(|&i| g[i] > 0)
            .map(|i| (i / SIDE, i % SIDE))
            .collect();
        assert!(!lit.is_empty());
        assert!(lit.iter().all(|&(x, y)| x >= 65 && y >= 65));
        assert_eq!(g[69 * SIDE + 69], 255);
        // s = -1 maps to pixel 0: the upper-right quarter (plus the centre lines).
        let g = gray_ball(-1.0, -1.0);
        assert_eq!(g[0], 255);
        assert!(
            (0..PIXELS)
                .filter(|&i| g[i] > 0)
                .all(|i| i / SIDE <= 5 && i % SIDE <= 5)
        );
        // Anything, anywhere: never panics; far away gives a blank image.
        let mut out = vec![0.5f32; PIXELS];
        for &s in &[-1e300, -1e9, -3.0, -1.5, -1.2, 1.2, 1.5, 3.0, 1e9, 1e300] {
            for &t in &[-1.0, 0.0, 1.0, s] {
                render_ball_into(s, t, &mut out);
                assert!(out.iter().all(|v| (0.0..=1.0).contains(v)));
                render_arrow_into(s, t, s, &mut out);
                assert!(out.iter().all(|v| (0.0..=1.0).contains(v)));
                render_arrow_into(t, t, s, &mut out);
                assert!(out.iter().all(|v| (0.0..=1.0).contains(v)));
            }
        }
        render_ball_into(5.0, 0.0, &mut out);
        assert!(out.iter().all(|&v| v == 0.0));
        render_arrow_into(0.0, -2.0, 0.3, &mut out);
        assert!(out.iter().all(|&v| v == 0.0));
        render_arrow_into(f64::NAN, 0.0, 0.3, &mut out);
        assert!(out.iter().all(|&v| v == 0.0));
        render_arrow_into(0.0, 0.0, f64::INFINITY, &mut out);
        assert!(out.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn arrow_shape() {
        // A dart of about 130 pixels, tip opposite to the angle's direction (r = (angle+1) pi).
        for &a in &[-1.0, 0.0, 0.6, 0.999, -0.3] {
            let g = gray_arrow(0.0, 0.0, a);
            let nz = g.iter().filter(|&&v| v > 0).count();
            assert!((110..=150).contains(&nz), "angle {a}: {nz} pixels");
            assert_eq!(g[35 * SIDE + 35], 255, "centre lit");
        }
        // angle 0 -> r = pi: the tip is at x = 25 (the arrow points toward -x).
        let v = arrow_vertices(0.0, 0.0, 0.0).unwrap();
        assert_eq!(v[0], (25, 35));
        assert_eq!(v[2], (35, 35));
        let g = gray_arrow(0.0, 0.0, 0.0);
        assert!(g[25 * SIDE + 35] > 0);
        assert!(g[44 * SIDE + 35] == 0);
    }

    #[test]
    fn into_matches_allocating_and_gray() {
        let mut out = vec![0.0f32; PIXELS];
        let mut g = vec![0u8; PIXELS];
        render_arrow_into(0.3, -0.2, 0.7, &mut out);
        assert_eq!(render_arrow(0.3, -0.2, 0.7).0, out);
        render_arrow_gray(0.3, -0.2, 0.7, &mut g);
        let max = f32::from(*g.iter().max().unwrap());
        for i in 0..PIXELS {
            assert_eq!(out[i], f32::from(g[i]) / max);
        }
    }

    #[test]
    fn png_grid_places_the_cells_with_gaps() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b, c) = (
            render_ball(-0.9, -0.9),
            render_ball(0.0, 0.0),
            render_ball(0.9, 0.9),
        );
        let p = dir.path().join("grid.png");
        write_png_grid(&[&a.0, &b.0, &c.0], 2, 1, &p).unwrap();
        let dec = png::Decoder::new(std::io::BufReader::new(File::open(&p).unwrap()));
        let mut reader = dec.read_info().unwrap();
        let mut buf = vec![0u8; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        let w = 2 * 70 + GRID_GAP;
        assert_eq!((info.width as usize, info.height as usize), (w, w));
        // The gap column is gray; the empty fourth cell too.
        assert_eq!(buf[10 * w + 70], 128);
        assert_eq!(buf[(72 + 10) * w + 72 + 10], 128);
        // Each cell is its image, y flipped: pixel (x, y) at row 69 - y.
        let at = |r0: usize, c0: usize, img: &Image70, x: usize, y: usize| {
            assert_eq!(
                buf[(r0 + 69 - y) * w + c0 + x],
                (img.0[x * 70 + y] * 255.0).round() as u8
            )
        };
        for (x, y) in [(3, 3), (35, 35), (66, 66), (10, 50)] {
            at(0, 0, &a, x, y);
            at(0, 72, &b, x, y);
            at(72, 0, &c, x, y);
        }
        assert!(write_png_grid(&[&a.0[..10]], 1, 1, &p).is_err());
    }

    #[test]
    fn writers_roundtrip() {
        let dir = tempfile::tempdir().unwrap();
        let img = render_ball(0.6, 0.6);
        let npy = dir.path().join("ball.npy");
        write_npy(&img, &npy).unwrap();
        let bytes = std::fs::read(&npy).unwrap();
        let arr = npyz::NpyFile::new(&bytes[..]).unwrap();
        assert_eq!(arr.shape(), &[70, 70]);
        assert_eq!(arr.order(), npyz::Order::C);
        let data: Vec<f32> = arr.into_vec().unwrap();
        assert_eq!(data, img.0);

        let pngp = dir.path().join("ball.png");
        write_png(&img, &pngp).unwrap();
        let dec = png::Decoder::new(std::io::BufReader::new(File::open(&pngp).unwrap()));
        let mut reader = dec.read_info().unwrap();
        let mut buf = vec![0u8; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (280, 280));
        assert_eq!(info.color_type, png::ColorType::Grayscale);
        // Ball centre (56, 56) in world coordinates: column 56*4, row (69-56)*4.
        assert_eq!(buf[(69 - 56) * 4 * 280 + 56 * 4], 255);
        // A ball at high y appears near the top of the picture.
        let img = render_ball(0.0, 0.9);
        write_png(&img, &pngp).unwrap();
        let dec = png::Decoder::new(std::io::BufReader::new(File::open(&pngp).unwrap()));
        let mut reader = dec.read_info().unwrap();
        reader.next_frame(&mut buf).unwrap();
        let first_lit_row = buf
            .chunks_exact(280)
            .position(|r| r.iter().any(|&p| p > 0))
            .unwrap();
        assert!(first_lit_row < 4 * 10, "row {first_lit_row}");

        let bad = Image70(vec![0.0; 10]);
        assert!(matches!(
            write_npy(&bad, &npy),
            Err(RenderError::BadLength { .. })
        ));
        let missing = dir.path().join("no/such/dir/x.png");
        assert!(matches!(
            write_png(&img, &missing),
            Err(RenderError::Io { .. })
        ));
    }
}
