//! The texture atlas: every image at its own size, shelf-packed into the square pages of one
//! texture array (lavapipe has no binding arrays). Shaders wrap and filter texel by texel
//! inside the image's own rectangle, so neighbours never bleed into each other.

use super::layout::{TEX_COORD_MASK, TEX_SIZE_MASK};
use crate::scene::Texture;

/// Largest page side: every Vulkan, Metal and DX12 device has 2D textures of 8192 (the WebGPU
/// default), and offsets within a page must fit the atlas word's 12 bits.
pub const MAX_PAGE_SIDE: u32 = TEX_COORD_MASK + 1;
/// Pages: the atlas word's page byte, less the value NO_TEXTURE takes.
pub const MAX_PAGES: u32 = 255;
/// The atlas's budget. Beyond it the largest images are halved, with a warning naming them.
pub const TEXTURE_BUDGET_BYTES: u64 = 512 << 20;

const _: () = assert!(MAX_PAGE_SIDE - 1 <= TEX_SIZE_MASK);

/// Where one image sits in the atlas, at the size it is stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Placement {
    pub page: u32,
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// The scene's images packed for the kernels.
#[derive(Clone, Debug, Default)]
pub struct TextureAtlas {
    /// `pages` pages of `side`² RGBA8 texels, page after page, rows top to bottom.
    pub texels: Vec<u32>,
    pub side: u32,
    pub pages: u32,
    /// One per `Scene::textures`, in order.
    pub placements: Vec<Placement>,
    /// One line per image stored smaller than it came.
    pub warnings: Vec<String>,
}

impl TextureAtlas {
    pub fn bytes(&self) -> u64 {
        self.texels.len() as u64 * 4
    }

    /// The texels the images themselves cover, over those of the pages (1: no waste).
    pub fn occupancy(&self) -> f64 {
        let used: u64 = self.placements.iter().map(|p| p.width as u64 * p.height as u64).sum();
        used as f64 / (self.texels.len() as f64).max(1.0)
    }
}

/// Shelf packing of `sizes` into pages of `side`²: tallest first, each image on the first
/// shelf with room, else on a new shelf, else on a new page. None: an image wider or taller
/// than a page.
pub fn shelf_pack(sizes: &[(u32, u32)], side: u32) -> Option<(Vec<Placement>, u32)> {
    struct Shelf {
        page: u32,
        y: u32,
        height: u32,
        x: u32,
    }
    let mut order: Vec<usize> = (0..sizes.len()).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(sizes[i].1), std::cmp::Reverse(sizes[i].0)));
    let mut placements = vec![Placement::default(); sizes.len()];
    let mut shelves: Vec<Shelf> = Vec::new();
    // The height used on the last page; earlier pages are closed.
    let (mut pages, mut page_top) = (0u32, side);
    for i in order {
        let (w, h) = sizes[i];
        if w > side || h > side {
            return None;
        }
        let shelf = match shelves.iter_mut().position(|s| h <= s.height && s.x + w <= side) {
            Some(s) => s,
            None => {
                if page_top + h > side {
                    pages += 1;
                    page_top = 0;
                }
                shelves.push(Shelf { page: pages - 1, y: page_top, height: h, x: 0 });
                page_top += h;
                shelves.len() - 1
            }
        };
        let s = &mut shelves[shelf];
        placements[i] = Placement { page: s.page, x: s.x, y: s.y, width: w, height: h };
        s.x += w;
    }
    Some((placements, pages))
}

/// The page side (a power of two, from the largest image's to MAX_PAGE_SIDE) whose packing
/// takes the fewest bytes within MAX_PAGES pages (any within before any beyond); ties go to
/// the smaller page.
fn best_packing(sizes: &[(u32, u32)]) -> (Vec<Placement>, u32, u32) {
    let largest = sizes.iter().map(|&(w, h)| w.max(h)).max().unwrap_or(1);
    let mut side = largest.next_power_of_two().min(MAX_PAGE_SIDE);
    let mut best: Option<(Vec<Placement>, u32, u32)> = None;
    while side <= MAX_PAGE_SIDE {
        if let Some((placements, pages)) = shelf_pack(sizes, side) {
            let key = |s: u32, p: u32| (p > MAX_PAGES, p as u64 * (s as u64).pow(2));
            if best.as_ref().is_none_or(|b| key(side, pages) < key(b.1, b.2)) {
                best = Some((placements, side, pages));
            }
        }
        side *= 2;
    }
    // Every size is within MAX_PAGE_SIDE, so the largest page always packs.
    best.unwrap_or_else(|| (vec![Placement::default(); sizes.len()], 1, 1))
}

fn area(s: &(u32, u32)) -> u64 {
    s.0 as u64 * s.1 as u64
}

fn halve(s: &mut (u32, u32)) {
    *s = ((s.0 / 2).max(1), (s.1 / 2).max(1));
}

/// Halves the largest images (by area; ties: the first) until all take at most `target`
/// bytes or every image is one texel.
fn shrink_to(sizes: &mut [(u32, u32)], target: u64) {
    use std::cmp::Reverse;
    let mut total = sizes.iter().map(area).sum::<u64>() * 4;
    let mut heap: std::collections::BinaryHeap<(u64, Reverse<usize>)> =
        sizes.iter().enumerate().map(|(i, s)| (area(s), Reverse(i))).collect();
    while total > target {
        let Some((a, Reverse(i))) = heap.pop() else { break };
        if a <= 1 {
            break;
        }
        halve(&mut sizes[i]);
        total = total - a * 4 + area(&sizes[i]) * 4;
        heap.push((area(&sizes[i]), Reverse(i)));
    }
}

/// The sizes images of `sizes` are stored at: each within a page, and the largest halved
/// (both axes) until the packed atlas fits `budget` bytes and MAX_PAGES pages.
pub fn atlas_sizes(sizes: &[(u32, u32)], budget: u64) -> Vec<(u32, u32)> {
    let mut sizes: Vec<(u32, u32)> = sizes
        .iter()
        .map(|&(w, h)| {
            let (w, h) = (w.max(1), h.max(1));
            let scale = (MAX_PAGE_SIDE as f64 / w.max(h) as f64).min(1.0);
            (((w as f64 * scale).round() as u32).max(1), ((h as f64 * scale).round() as u32).max(1))
        })
        .collect();
    // A page holds the longest side: one page must fit the budget.
    let page_bytes = |sizes: &[(u32, u32)]| {
        (sizes.iter().map(|s| s.0.max(s.1)).max().unwrap_or(1).next_power_of_two() as u64).pow(2) * 4
    };
    while page_bytes(&sizes) > budget && sizes.iter().any(|s| area(s) > 1) {
        let longest = sizes.iter().map(|s| s.0.max(s.1)).max().unwrap_or(1);
        sizes.iter_mut().filter(|s| s.0.max(s.1) == longest).for_each(halve);
    }
    // Then by area alone (cheap), then by the packing itself: pages waste some room, so the
    // next target is the images' bytes scaled by how well the last packing used its pages.
    shrink_to(&mut sizes, budget);
    loop {
        let (_, side, pages) = best_packing(&sizes);
        let packed = pages as u64 * (side as u64).pow(2) * 4;
        if (packed <= budget && pages <= MAX_PAGES) || sizes.iter().all(|s| area(s) <= 1) {
            return sizes;
        }
        let images = sizes.iter().map(area).sum::<u64>() * 4;
        let over = (packed as f64 / budget as f64).max(pages as f64 / MAX_PAGES as f64);
        shrink_to(&mut sizes, ((images as f64 / over) as u64).min(images - 1));
    }
}

/// Every image in the atlas at its own size (shrunk, with a warning, only to fit a page or
/// the budget).
pub fn pack_textures(textures: &[Texture]) -> TextureAtlas {
    pack_textures_within(textures, TEXTURE_BUDGET_BYTES)
}

pub fn pack_textures_within(textures: &[Texture], budget: u64) -> TextureAtlas {
    if textures.is_empty() {
        return TextureAtlas { texels: vec![u32::MAX], side: 1, pages: 1, ..Default::default() };
    }
    let sizes = atlas_sizes(&textures.iter().map(|t| (t.width, t.height)).collect::<Vec<_>>(), budget);
    let (placements, side, pages) = best_packing(&sizes);
    use rayon::prelude::*;
    let images: Vec<Vec<u32>> = textures
        .par_iter()
        .zip(&sizes)
        .map(|(t, &(w, h))| {
            let image = image::RgbaImage::from_raw(t.width, t.height, t.rgba.clone())
                .unwrap_or_else(|| image::RgbaImage::new(t.width.max(1), t.height.max(1)));
            let image = if image.dimensions() == (w, h) {
                image
            } else {
                image::imageops::resize(&image, w, h, image::imageops::FilterType::Triangle)
            };
            image.pixels().map(|p| u32::from_le_bytes(p.0)).collect()
        })
        .collect();
    let side_us = side as usize;
    let mut texels = vec![0u32; pages as usize * side_us * side_us];
    for (image, p) in images.iter().zip(&placements) {
        let w = p.width as usize;
        for (row, line) in image.chunks_exact(w).enumerate() {
            let start = (p.page as usize * side_us + p.y as usize + row) * side_us + p.x as usize;
            texels[start..start + w].copy_from_slice(line);
        }
    }
    let warnings = textures
        .iter()
        .zip(&sizes)
        .filter(|(t, s)| (t.width, t.height) != **s)
        .map(|(t, s)| {
            format!(
                "texture {:?} is stored at {}x{} instead of {}x{} (images are kept within {}² \
                 texels and all of them within {} MiB)",
                t.name,
                s.0,
                s.1,
                t.width,
                t.height,
                MAX_PAGE_SIDE,
                budget >> 20
            )
        })
        .collect();
    TextureAtlas { texels, side, pages, placements, warnings }
}
