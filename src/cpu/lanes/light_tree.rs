//! The light tree's walk for a packet of paths: each lane's walk is `sample_light_tree`'s,
//! step for step, but the lanes take their steps side by side, level by level. One walk is a
//! chain of dependent roots and divisions (about a hundred cycles a level); the walks of
//! different paths are independent, so the core overlaps them.

use super::{LANES, lanes_of};
use crate::cpu::light_tree::{LightContext, child_importance, choose_child, group_shares, load_light_node};
use crate::packed::{LIGHT_LEAF, LIGHT_TWO_SIDED, LightGroup, PackedScene};
use crate::params::Params;

/// `sample_light_tree` from `ctx[i]` with number `u[i]` for the lanes `i` of `mask`:
/// (emitter, probability) per lane, (0, 0) elsewhere.
pub fn sample_light_tree_lanes(
    scene: &PackedScene,
    params: &Params,
    ctx: &[LightContext; LANES],
    u: &[f32; LANES],
    mask: u32,
) -> [(u32, f32); LANES] {
    let mut out = [(0u32, 0.0f32); LANES];
    if mask == 0 {
        return out;
    }
    let root = load_light_node(scene, params, 0);
    if root.leaf {
        for i in lanes_of(mask) {
            out[i] = (root.index, if child_importance(scene, params, &ctx[i], &root).x > 0.0 { 1.0 } else { 0.0 });
        }
        return out;
    }
    let first: &LightGroup = &scene.light_groups[0];
    let mut group = [first; LANES];
    let mut u = *u;
    let mut pmf = [1.0f32; LANES];
    let mut walking = mask;
    while walking != 0 {
        for i in lanes_of(walking) {
            let Some(shares) = group_shares(scene, params, &ctx[i], group[i]) else {
                out[i] = (0, 0.0);
                walking &= !(1 << i);
                continue;
            };
            let (slot, rescaled) = choose_child(shares, u[i]);
            u[i] = rescaled;
            pmf[i] *= shares[slot];
            let next = group[i].next[slot];
            if next & LIGHT_LEAF != 0 {
                out[i] = (next & !(LIGHT_LEAF | LIGHT_TWO_SIDED), pmf[i]);
                walking &= !(1 << i);
                continue;
            }
            group[i] = &scene.light_groups[(next & !LIGHT_TWO_SIDED) as usize];
        }
    }
    out
}
