//! A window of the image: what a farm part or a crop renders.

/// A crop window of the image (the whole image by default).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Tile {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl Tile {
    /// Whether the tile is non-empty and lies inside a `width`×`height` image (no overflow).
    pub fn fits(&self, width: u32, height: u32) -> bool {
        let inside = |o: u32, n: u32, side: u32| n > 0 && o.checked_add(n).is_some_and(|end| end <= side);
        inside(self.x, self.width, width) && inside(self.y, self.height, height)
    }

    pub fn overlaps(&self, o: &Tile) -> bool {
        let span = |a: u32, n: u32| a as u64..a as u64 + n as u64;
        let (ax, ay, bx, by) =
            (span(self.x, self.width), span(self.y, self.height), span(o.x, o.width), span(o.y, o.height));
        ax.start < bx.end && bx.start < ax.end && ay.start < by.end && by.start < ay.end
    }
}
