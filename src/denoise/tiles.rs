//! Cutting an image into tiles the network can run on within a memory limit.
//!
//! Each tile writes only its interior and reads `TILE_OVERLAP` pixels beyond it on every
//! side (more than half the receptive field), so the pixels it writes depend on the same
//! inputs as in a whole-image run. Tile origins are multiples of 16, so the poolings see the
//! same 2×2 grids. A denoise in tiles therefore equals a whole one (up to the order of float
//! additions inside a layer).

use super::network::{ALIGNMENT, TILE_OVERLAP};

/// One tile: its tensor's window in image pixels (the origin a multiple of 16, the sides
/// multiples of 16, possibly reaching past the image, where the input is zero) and the
/// interior it writes `(x, y, width, height)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tile {
    pub x: usize,
    pub y: usize,
    pub width: usize,
    pub height: usize,
    pub interior: (usize, usize, usize, usize),
}

/// Tiles covering a `width`×`height` image, each tensor at most `max_pixels` pixels where
/// possible: the grid of the fewest tensor pixels in all (overlaps count) among those whose
/// tiles fit; when none fits, the finest grid (tiles of 16 + 2·overlap a side at most).
pub fn plan_tiles(width: usize, height: usize, max_pixels: usize) -> Vec<Tile> {
    let (pw, ph) = (width.next_multiple_of(ALIGNMENT), height.next_multiple_of(ALIGNMENT));
    // Tensor spans along one axis cut into `n` interiors: (origin, size, interior origin, size).
    let spans = |size: usize, padded: usize, n: usize| -> Vec<(usize, usize, usize, usize)> {
        let step = size.div_ceil(n).next_multiple_of(ALIGNMENT);
        (0..size.div_ceil(step))
            .map(|i| {
                let (a, b) = (i * step, ((i + 1) * step).min(size));
                let t0 = a.saturating_sub(TILE_OVERLAP);
                let t1 = (b + TILE_OVERLAP).min(padded).next_multiple_of(ALIGNMENT);
                (t0, t1 - t0, a, b - a)
            })
            .collect()
    };
    let largest = |v: &[(usize, usize, usize, usize)]| v.iter().map(|s| s.1).max().unwrap_or(0);
    let total = |v: &[(usize, usize, usize, usize)]| v.iter().map(|s| s.1).sum::<usize>();
    let (most_x, most_y) = (width.div_ceil(ALIGNMENT), height.div_ceil(ALIGNMENT));
    let mut best: Option<(usize, Vec<_>, Vec<_>)> = None;
    // Grids up to 64 tiles a side are tried (more only when they must be).
    for nx in 1..=most_x.min(64) {
        let xs = spans(width, pw, nx);
        for ny in 1..=most_y.min(64) {
            let ys = spans(height, ph, ny);
            if largest(&xs) * largest(&ys) > max_pixels {
                continue;
            }
            let cost = total(&xs) * total(&ys);
            if best.as_ref().is_none_or(|b| cost < b.0) {
                best = Some((cost, xs.clone(), ys));
            }
            break;
        }
    }
    let (xs, ys) = match best {
        Some((_, xs, ys)) => (xs, ys),
        None => (spans(width, pw, most_x), spans(height, ph, most_y)),
    };
    let mut tiles = Vec::with_capacity(xs.len() * ys.len());
    for &(ty, th, iy, ih) in &ys {
        for &(tx, tw, ix, iw) in &xs {
            tiles.push(Tile { x: tx, y: ty, width: tw, height: th, interior: (ix, iy, iw, ih) });
        }
    }
    tiles
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_every_pixel_once_with_their_overlap() {
        for (w, h, max) in [(20, 12, 1 << 20), (240, 224, 224 * 224), (1000, 700, 300 * 300), (3000, 50, 500_000)] {
            let tiles = plan_tiles(w, h, max);
            let mut hits = vec![0u8; w * h];
            for t in &tiles {
                assert!(t.x % 16 == 0 && t.y % 16 == 0 && t.width % 16 == 0 && t.height % 16 == 0, "{t:?}");
                let (ix, iy, iw, ih) = t.interior;
                for y in iy..iy + ih {
                    for x in ix..ix + iw {
                        hits[y * w + x] += 1;
                    }
                }
                // The tensor reaches the overlap beyond the interior, or the image's edge.
                assert!(t.x + TILE_OVERLAP <= ix || t.x == 0, "{t:?}");
                assert!(t.y + TILE_OVERLAP <= iy || t.y == 0, "{t:?}");
                assert!(ix + iw + TILE_OVERLAP <= t.x + t.width || t.x + t.width >= w, "{t:?}");
                assert!(iy + ih + TILE_OVERLAP <= t.y + t.height || t.y + t.height >= h, "{t:?}");
                if tiles.len() > 1 {
                    assert!(t.width * t.height <= max.max((16 + 2 * TILE_OVERLAP).pow(2)), "{t:?} over {max}");
                }
                assert!(t.x + t.width <= w.next_multiple_of(16) && t.y + t.height <= h.next_multiple_of(16));
            }
            assert!(hits.iter().all(|&n| n == 1), "{w}x{h}: every pixel written once");
        }
        assert_eq!(plan_tiles(20, 12, 1 << 20).len(), 1);
        assert!(plan_tiles(240, 224, 224 * 224).len() > 1);
        // Two tiles where two suffice.
        assert_eq!(plan_tiles(320, 32, 260 * 32).len(), 2);
    }
}
