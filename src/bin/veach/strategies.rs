//! `veach strategies`: Veach's four direct-lighting estimators at equal spp, side by side.

use crate::args::StrategiesArgs;
use std::time::Instant;
use veach::{Error, SamplerKind, Settings, Strategy};

/// Height of the label bar above the panels: two text lines of 14 px and a margin.
const LABEL_BAR: u32 = 14 * 3;

pub fn run(args: &StrategiesArgs) -> Result<(), Error> {
    if veach::output::check_output(&args.output)? != veach::output::Format::Png {
        return Err(Error::Input(format!("{}: the contact sheet is a .png", args.output.display())));
    }
    if args.spp == 0 {
        return Err(Error::Input("--spp must be at least 1".into()));
    }
    let (w, h) = (args.width, args.height);
    let mut settings = Settings {
        width: w,
        height: h,
        max_depth: args.max_depth,
        seed: args.seed,
        sampler: SamplerKind::Sobol,
        ..Settings::default()
    };
    args.look.apply(&mut settings);
    let loaded = veach::load_with(&args.scene, &settings.load_options())?;
    crate::warn_all(&args.scene, &loaded.warnings);
    let packed = veach::PackedScene::new(&loaded.scene);
    crate::warn_all(&args.scene, &packed.warnings);
    // One renderer for the four panels: only the estimator changes between them.
    let (mut renderer, _) = crate::open_renderer(packed, &loaded.camera, &settings, args.backend)?;
    let mut sheet = image::RgbImage::new(4 * w, h + LABEL_BAR);
    for (k, strategy) in Strategy::ALL.into_iter().enumerate() {
        renderer.reset(&loaded.camera, &Settings { strategy, ..settings.clone() })?;
        let t = Instant::now();
        renderer.render_samples(0, args.spp)?;
        let film = renderer.film()?;
        eprintln!("veach: {strategy:?}: {} spp in {:.2} s", args.spp, t.elapsed().as_secs_f64());
        let panel = veach::output::tonemap(&film, args.exposure, args.tonemap);
        image::imageops::replace(&mut sheet, &panel, (k as u32 * w) as i64, LABEL_BAR as i64);
        let name = strategy.label();
        let scale = if crate::label::text_width(name, 2) + 8 <= w { 2 } else { 1 };
        crate::label::draw_text(&mut sheet, k as u32 * w + 6, 6, name, scale, [255, 255, 255]);
        let sub = format!("{} SPP", args.spp);
        crate::label::draw_text(&mut sheet, k as u32 * w + 6, 6 + 8 * scale + 4, &sub, 1, [180, 180, 180]);
    }
    veach::output::write_png(&sheet, &args.output)?;
    eprintln!("veach: wrote {}", args.output.display());
    Ok(())
}
