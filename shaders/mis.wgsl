// Multiple importance sampling weights for one sample from each of two strategies
// (n_f = n_g = 1). Twin: src/cpu/mis.rs.
#include "common.wgsl"

fn balance_heuristic(pdf_f: f32, pdf_g: f32) -> f32 {
    if (pdf_f <= 0.0) {
        return 0.0;
    }
    return 1.0 / (1.0 + pdf_g / pdf_f);
}

// Written as 1 / (1 + (g/f)²) so large pdfs do not overflow when squared.
fn power_heuristic(pdf_f: f32, pdf_g: f32) -> f32 {
    if (pdf_f <= 0.0) {
        return 0.0;
    }
    let r = pdf_g / pdf_f;
    return 1.0 / (1.0 + r * r);
}

// Weight of a sample drawn by the strategy with density `pdf_f`, the other having `pdf_g`.
fn mis_weight(strategy: u32, pdf_f: f32, pdf_g: f32) -> f32 {
    if (strategy == STRATEGY_MIS_BALANCE) {
        return balance_heuristic(pdf_f, pdf_g);
    }
    return power_heuristic(pdf_f, pdf_g);
}
