//! The environment as the kernel reads it: texels with the CDFs of its sampling distribution.

use super::materials::luminance;

/// The environment's texels with the CDFs of the piecewise-constant distribution
/// ∝ luminance × sin θ (marginal over rows, conditional within each row).
pub fn pack_environment(map: &crate::scene::EnvironmentMap) -> (Vec<[f32; 4]>, u32, u32, f32) {
    let (w, h) = (map.width as usize, map.height as usize);
    let mut env = Vec::with_capacity(w * h + h);
    let mut row_sums = Vec::with_capacity(h);
    for i in 0..h {
        let sin_theta = (std::f64::consts::PI * (i as f64 + 0.5) / h as f64).sin();
        let row = &map.texels[i * w..(i + 1) * w];
        let func: Vec<f64> = row.iter().map(|c| luminance(*c) as f64 * sin_theta).collect();
        let sum: f64 = func.iter().sum();
        let mut acc = 0.0;
        for (j, c) in row.iter().enumerate() {
            acc += func[j];
            let cdf = if sum > 0.0 { if j + 1 == w { 1.0 } else { acc / sum } } else { (j + 1) as f64 / w as f64 };
            env.push([c.x, c.y, c.z, cdf as f32]);
        }
        row_sums.push(sum);
    }
    let total: f64 = row_sums.iter().sum();
    let mut acc = 0.0;
    for (i, s) in row_sums.iter().enumerate() {
        acc += s;
        let cdf = if total > 0.0 { if i + 1 == h { 1.0 } else { acc / total } } else { 0.0 };
        env.push([cdf as f32, 0.0, 0.0, 0.0]);
    }
    (env, w as u32, h as u32, total as f32)
}
