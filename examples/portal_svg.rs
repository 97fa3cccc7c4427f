//! Draws the portal drop as an SVG of outlines at a few instants (the box,
//! its clone while it straddles, the floor, the wall and the two portals),
//! written to `docs/portal_crossing.svg`. Run with
//! `cargo run --release --example portal_svg`.

use janus2d::prelude::{BodyHandle, Shape, World, WorldDef};
use janus2d_testbed::scenes::{self, DT};
use plotters::prelude::*;

/// World outlines of every shape of a body (polygons as vertex loops).
// `Real` is f32 or f64 by feature: the cast is the identity in f64.
#[allow(clippy::unnecessary_cast)]
fn outlines(world: &World, body: BodyHandle) -> Vec<Vec<(f64, f64)>> {
    let xf = world.transform(body).unwrap();
    let mut out = Vec::new();
    for s in world.body_shapes(body).unwrap() {
        if let Shape::Polygon(p) = world.shape(s).unwrap().geometry {
            let mut pts: Vec<(f64, f64)> = p.vertices[..p.count]
                .iter()
                .map(|v| {
                    let w = xf.apply(*v);
                    (w.x as f64, w.y as f64)
                })
                .collect();
            pts.push(pts[0]);
            out.push(pts);
        }
    }
    out
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (mut scene, _) = scenes::portal_drop(&WorldDef::default());
    let world = &mut scene.world;
    let path = "docs/portal_crossing.svg";
    let root = SVGBackend::new(path, (900, 520)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption("Portal drop: the box (blue) falls into the floor portal, its clone (orange) leaves the wall portal", ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(40)
        .build_cartesian_2d(-22.0f64..3.0f64, -1.5f64..7.0f64)?;
    chart
        .configure_mesh()
        .x_desc("x [m]")
        .y_desc("y [m]")
        .draw()?;
    let statics: Vec<BodyHandle> = world.body_handles().filter(|h| *h != scene.probe).collect();
    for b in &statics {
        for o in outlines(world, *b) {
            chart.draw_series(std::iter::once(plotters::element::Polygon::new(
                o,
                RGBColor(200, 200, 200).filled(),
            )))?;
        }
    }
    // The two apertures.
    chart.draw_series(LineSeries::new(
        vec![(-1.0, 0.0), (1.0, 0.0)],
        RED.stroke_width(4),
    ))?;
    chart.draw_series(LineSeries::new(
        vec![(-19.5, 4.0), (-19.5, 6.0)],
        RED.stroke_width(4),
    ))?;
    let mut frame = 0;
    for step in 1..=120 {
        world.step(DT)?;
        let crossing = world.crossing_count() > 0;
        let keep =
            matches!(step, 30 | 50) || (crossing && step % 2 == 0) || matches!(step, 75 | 90);
        if !keep {
            continue;
        }
        frame += 1;
        for o in outlines(world, scene.probe) {
            chart.draw_series(std::iter::once(PathElement::new(o, BLUE.stroke_width(2))))?;
        }
        if let Some(clone) = world.clone_of(scene.probe) {
            for o in outlines(world, clone) {
                chart.draw_series(std::iter::once(PathElement::new(
                    o,
                    RGBColor(230, 120, 0).stroke_width(2),
                )))?;
            }
        }
    }
    root.present()?;
    println!("wrote {path} ({frame} frames)");
    Ok(())
}
