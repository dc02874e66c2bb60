//! Light records: the alias table over emissive triangles and the punctual lights.

use super::layout::{LightEntry, PUNCTUAL_DIRECTIONAL, PUNCTUAL_POINT, PUNCTUAL_SPOT, Punctual};
use crate::scene::{PunctualKind, PunctualLight};

/// The punctual light as four rows of the light-data buffer.
pub fn pack_punctual(l: &PunctualLight) -> Punctual {
    let (kind, cos_inner, cos_outer) = match l.kind {
        PunctualKind::Point => (PUNCTUAL_POINT, -1.0, -1.0),
        PunctualKind::Spot { cos_inner, cos_outer } => (PUNCTUAL_SPOT, cos_inner, cos_outer),
        PunctualKind::Directional => (PUNCTUAL_DIRECTIONAL, -1.0, -1.0),
    };
    Punctual {
        position: l.position.into(),
        kind,
        direction: l.direction.into(),
        range: if l.range.is_finite() { l.range } else { 0.0 },
        intensity: l.intensity.into(),
        cos_inner,
        cos_outer,
        pad: [0.0; 3],
    }
}

/// Vose's alias method: O(1) sampling of a discrete distribution, built in f64.
pub fn build_alias_table(items: &[u32], weights: &[f64]) -> Vec<LightEntry> {
    let n = items.len();
    if n == 0 {
        return Vec::new();
    }
    let total: f64 = weights.iter().sum();
    let mut scaled: Vec<f64> = weights.iter().map(|w| w * n as f64 / total).collect();
    let mut alias: Vec<usize> = (0..n).collect();
    let mut prob = vec![1.0f64; n];
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
    while let (Some(s), Some(&l)) = (small.pop(), large.last()) {
        prob[s] = scaled[s];
        alias[s] = l;
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    (0..n)
        .map(|i| LightEntry {
            triangle: items[i],
            alias_slot: alias[i] as u32,
            prob: prob[i] as f32,
            pmf: (weights[i] / total) as f32,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alias_table_reproduces_weights() {
        let w = [1.0, 2.0, 3.0, 10.0, 0.5];
        let t = build_alias_table(&[0, 1, 2, 3, 4], &w);
        let n = t.len() as f64;
        let mut p = [0.0f64; 5];
        for (i, e) in t.iter().enumerate() {
            p[i] += e.prob as f64 / n;
            p[e.alias_slot as usize] += (1.0 - e.prob as f64) / n;
        }
        let total: f64 = w.iter().sum();
        for i in 0..5 {
            assert!((p[i] - w[i] / total).abs() < 1e-6, "{i}: {} vs {}", p[i], w[i] / total);
        }
    }
}
