//! `veach view`: the interactive window.

use crate::args::ViewArgs;
use veach::Error;

pub fn run(args: ViewArgs) -> Result<(), Error> {
    if let Some(shot) = &args.screenshot
        && veach::output::check_output(shot)? != veach::output::Format::Png
    {
        return Err(Error::Input(format!("{}: screenshots are .png", shot.display())));
    }
    veach::viewer::run(veach::viewer::ViewOptions {
        scene: args.scene,
        screenshot: args.screenshot,
        frames: args.frames,
        max_depth: args.max_depth,
        env: args.env,
        env_color: args.env_color,
        window: args.window,
        render_scale: args.render_scale,
        backend: args.backend,
        heat_map: args.heat_map,
        denoise: args.denoise,
        noise_threshold: (args.noise_threshold > 0.0).then_some(args.noise_threshold),
    })
}
