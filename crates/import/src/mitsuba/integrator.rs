//! Mitsuba integrators → Prism's `path`. Mitsuba's max_depth counts path segments (1: emitters
//! seen directly, 2: direct lighting); Prism's counts bounces (1: direct lighting), so Prism's
//! max_depth = Mitsuba's − 1; Mitsuba's −1 (unlimited) becomes UNLIMITED_BOUNCES.

use serde_json::json;

use crate::error::ImportError;
use crate::mitsuba::props::Props;
use crate::mitsuba::xml::Element;
use crate::mitsuba::Ctx;

/// Prism has no unlimited depth; Russian roulette ends paths long before this many bounces.
pub const UNLIMITED_BOUNCES: i64 = 1024;

pub fn integrator(ctx: &mut Ctx, el: &Element) -> Result<(), ImportError> {
    let props = Props::new(el);
    let kind = props.plugin_type()?;
    match kind {
        "path" | "volpath" => {}
        "direct" => ctx.out.unsupported.note(
            "integrator direct",
            "imported as Prism's path with max_depth 1 (direct lighting; Prism samples it with MIS as path does)",
            &el.at,
        ),
        other => ctx.out.unsupported.note(
            format!("integrator type=\"{other}\""),
            "imported as Prism's path",
            &el.at,
        ),
    }
    let max_depth = if kind == "direct" {
        2
    } else {
        props.integer("max_depth")?.unwrap_or(-1)
    };
    let bounces = match max_depth {
        -1 => UNLIMITED_BOUNCES,
        d if d >= 2 => d - 1,
        d => {
            return Err(ImportError::at(
                &el.at,
                format!("integrator max_depth {d}: Prism's path needs at least one bounce (Mitsuba max_depth ≥ 2, or −1)"),
            ))
        }
    };
    let rr_depth = props.integer("rr_depth")?.unwrap_or(5);
    if props.boolean("hide_emitters")? == Some(true) {
        ctx.out.unsupported.note(
            "integrator hide_emitters",
            "ignored: Prism's path shows emitters seen directly",
            &el.at,
        );
    }
    ctx.integrator = Some((bounces, rr_depth));
    props.finish(&format!("integrator {kind}"), &mut ctx.out.unsupported);
    Ok(())
}

/// The integrator JSON once the sampler is known.
pub fn integrator_json(ctx: &Ctx) -> serde_json::Value {
    let (bounces, rr_depth) = ctx.integrator.unwrap_or((UNLIMITED_BOUNCES, 5));
    json!({"type": "path", "max_depth": bounces, "sampler": ctx.sampler, "mis": "power", "rr_depth": rr_depth})
}
