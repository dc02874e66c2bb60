//! Twin of `shaders/mis.wgsl`.

use crate::Strategy;

pub fn balance_heuristic(pdf_f: f32, pdf_g: f32) -> f32 {
    if pdf_f <= 0.0 {
        return 0.0;
    }
    1.0 / (1.0 + pdf_g / pdf_f)
}

pub fn power_heuristic(pdf_f: f32, pdf_g: f32) -> f32 {
    if pdf_f <= 0.0 {
        return 0.0;
    }
    let r = pdf_g / pdf_f;
    1.0 / (1.0 + r * r)
}

pub fn mis_weight(strategy: Strategy, pdf_f: f32, pdf_g: f32) -> f32 {
    match strategy {
        Strategy::MisBalance => balance_heuristic(pdf_f, pdf_g),
        _ => power_heuristic(pdf_f, pdf_g),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_of_two_strategies_sum_to_one() {
        for (a, b) in [(1.0, 1.0), (0.1, 7.0), (1e6, 3.0), (2.5, 1e-4)] {
            assert!((balance_heuristic(a, b) + balance_heuristic(b, a) - 1.0).abs() < 1e-6);
            assert!((power_heuristic(a, b) + power_heuristic(b, a) - 1.0).abs() < 1e-6);
        }
        assert_eq!(power_heuristic(0.0, 1.0), 0.0);
        assert!((power_heuristic(1.0, 2.0) - 0.2).abs() < 1e-7);
        assert!((balance_heuristic(1.0, 3.0) - 0.25).abs() < 1e-7);
    }
}
