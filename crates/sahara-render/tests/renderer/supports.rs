//! What each integrator supports is declared once and enforced by the
//! render: a combination an integrator cannot honour comes back as a
//! typed error before anything renders, never rendered without it.

use std::time::Duration;

use crate::common::settings;
use sahara_render::{
    builtin, render, render_watched, Adaptive, Aov, Feature, Integrator, IntegratorKind, Named,
    PixelWindow, Preview, RenderSettings, SettingsError, Support,
};

fn adaptive() -> Option<Adaptive> {
    Some(Adaptive {
        threshold: 0.05,
        min_spp: 2,
    })
}

fn sppm() -> Integrator {
    Integrator::Sppm {
        max_depth: 4,
        radius: 0.0,
        photons: 1000,
    }
}

fn refused(s: &RenderSettings) -> SettingsError {
    let scene = builtin::cornell_box();
    render(&scene, s, &|_| panic!("a refused render reported progress"))
        .expect_err("the render was not refused")
}

/// The error is the one of the integrator's declaration, with its reason.
fn assert_unsupported(e: SettingsError, integrator: IntegratorKind, feature: Feature) {
    let Support::No(reason) = integrator.supports().get(feature) else {
        panic!("{integrator} supports {feature:?}");
    };
    assert_eq!(
        e,
        SettingsError::Unsupported {
            integrator,
            feature,
            why: reason
        }
    );
    let text = e.to_string();
    assert!(
        !text.contains('\n') && text.contains(integrator.name()),
        "{text}"
    );
}

#[test]
fn adaptive_sppm_is_refused_not_dropped() {
    let mut s = settings(8, 8, 4, sppm());
    s.adaptive = adaptive();
    assert_unsupported(refused(&s), IntegratorKind::Sppm, Feature::Adaptive);
}

#[test]
fn sample_ranges_are_refused_where_iterations_depend_on_each_other() {
    let s = RenderSettings {
        samples: Some(0..2),
        ..settings(8, 8, 4, sppm())
    };
    assert_unsupported(refused(&s), IntegratorKind::Sppm, Feature::SampleRanges);
    // The whole range is no range.
    let whole = RenderSettings {
        samples: Some(0..4),
        ..s.clone()
    };
    assert!(render(&builtin::cornell_box(), &whole, &|_| {}).is_ok());
}

#[test]
fn light_tracing_refuses_parts_by_pixels_and_adaptive_sampling_but_renders_crops() {
    let scene = builtin::cornell_box();
    for integrator in [
        Integrator::Bdpt { max_depth: 3 },
        Integrator::LightPath { max_depth: 3 },
    ] {
        let kind = integrator.kind();
        let crop = RenderSettings {
            window: Some(PixelWindow {
                x0: 0,
                x1: 4,
                y0: 0,
                y1: 8,
            }),
            ..settings(8, 8, 2, integrator)
        };
        assert!(render(&scene, &crop, &|_| {}).is_ok(), "{kind}: a crop");
        let part = RenderSettings {
            part: true,
            ..crop.clone()
        };
        assert_unsupported(refused(&part), kind, Feature::PixelParts);
        // A part by samples of the whole frame is fine.
        let by_samples = RenderSettings {
            window: None,
            samples: Some(0..1),
            ..part.clone()
        };
        assert!(render(&scene, &by_samples, &|_| {}).is_ok(), "{kind}");
        let mut adaptive_settings = settings(8, 8, 2, integrator);
        adaptive_settings.adaptive = adaptive();
        assert_unsupported(refused(&adaptive_settings), kind, Feature::Adaptive);
    }
}

#[test]
fn render_passes_are_refused_by_the_integrators_that_cannot_make_them() {
    for &kind in IntegratorKind::ALL {
        let s = RenderSettings {
            aovs: vec![Aov::Albedo, Aov::Normal],
            ..settings(4, 4, 1, Integrator::from(kind))
        };
        let scene = builtin::cornell_box();
        match kind.supports().aovs {
            Support::Yes => assert!(render(&scene, &s, &|_| {}).is_ok(), "{kind}"),
            Support::No(_) => assert_unsupported(refused(&s), kind, Feature::Aovs),
        }
        assert_eq!(
            kind.require(Feature::Denoise).is_ok(),
            kind.supports().aovs.is_yes()
        );
    }
}

#[test]
fn adaptive_sampling_with_a_sample_range_is_refused_for_every_integrator() {
    let mut s = RenderSettings {
        samples: Some(0..2),
        ..settings(8, 8, 4, Integrator::default())
    };
    s.adaptive = adaptive();
    assert_eq!(
        refused(&s),
        SettingsError::AdaptiveSampleRange {
            samples: 0..2,
            spp: 4
        }
    );
}

/// SPPM hands its iterations to a preview as the other integrators hand
/// their passes, without changing the image.
#[test]
fn sppm_shows_previews_between_iterations() {
    let scene = builtin::cornell_box();
    let s = settings(8, 8, 3, sppm());
    let plain = render(&scene, &s, &|_| {}).unwrap();
    let mut seen = Vec::new();
    let watched = render_watched(
        &scene,
        &s,
        &|_| {},
        Some(Preview {
            every: Duration::ZERO,
            show: &mut |r| seen.push(r.stats.spp),
        }),
    )
    .unwrap();
    assert_eq!(seen, [1, 2]);
    assert_eq!(watched.film.pixels, plain.film.pixels);
}

/// A scene with a participating medium renders with the path tracer only
/// (as the volumetric path tracer, render passes included); the other
/// integrators refuse it rather than render it as if in vacuum.
#[test]
fn media_are_refused_by_the_integrators_that_cannot_trace_them() {
    let mut scene = builtin::cornell_box();
    let fog = scene.add_medium(sahara_render::Medium::homogeneous(
        glam::Vec3::splat(0.001),
        glam::Vec3::splat(0.002),
        0.0,
    ));
    scene.camera_medium = Some(fog);
    let base = settings(8, 8, 1, Integrator::from(IntegratorKind::Path));
    for integrator in [
        sppm(),
        Integrator::Bdpt { max_depth: 4 },
        Integrator::from(IntegratorKind::Distribution),
    ] {
        let mut s = base.clone();
        s.integrator = integrator;
        let e = render(&scene, &s, &|_| {}).expect_err("rendered a scene with media");
        assert_unsupported(e, integrator.kind(), Feature::Media);
    }
    let mut path = base.clone();
    path.integrator = Integrator::from(IntegratorKind::Path);
    assert!(render(&scene, &path, &|_| {}).is_ok());
    let passes = RenderSettings {
        aovs: vec![Aov::Albedo],
        ..path
    };
    assert!(render(&scene, &passes, &|_| {}).is_ok());
}
