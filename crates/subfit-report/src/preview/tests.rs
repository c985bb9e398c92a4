//! Tests of the preview rasterizer against analytic shapes.

use super::*;
use crate::error_color;

/// A UV sphere of radius `r` at the origin: `n_lon × (n_lat - 1) + 2` vertices.
pub(crate) fn uv_sphere(r: f64, n_lon: u32, n_lat: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    use std::f64::consts::PI;
    let mut p = vec![[0.0, r, 0.0]];
    for i in 1..n_lat {
        let th = PI * f64::from(i) / f64::from(n_lat);
        for j in 0..n_lon {
            let ph = 2.0 * PI * f64::from(j) / f64::from(n_lon);
            p.push([
                r * th.sin() * ph.cos(),
                r * th.cos(),
                r * th.sin() * ph.sin(),
            ]);
        }
    }
    p.push([0.0, -r, 0.0]);
    let south = p.len() as u32 - 1;
    let v = |i: u32, j: u32| 1 + (i - 1) * n_lon + j % n_lon;
    let mut t = Vec::new();
    for j in 0..n_lon {
        t.push([0, v(1, j + 1), v(1, j)]);
        t.push([south, v(n_lat - 1, j), v(n_lat - 1, j + 1)]);
    }
    for i in 1..n_lat - 1 {
        for j in 0..n_lon {
            t.push([v(i, j), v(i, j + 1), v(i + 1, j + 1)]);
            t.push([v(i, j), v(i + 1, j + 1), v(i + 1, j)]);
        }
    }
    (p, t)
}

/// Sum of pixel coverage for a black unlit mesh on white: `Σ (255 - r) / 255`.
fn coverage(img: &Image) -> f64 {
    img.rgb
        .chunks(3)
        .map(|c| f64::from(255 - c[0]) / 255.0)
        .sum()
}

fn flat_black(view: View) -> PreviewOptions {
    PreviewOptions {
        width: 320,
        height: 240,
        view,
        background: [255; 3],
        ambient: 1.0,
        ..Default::default()
    }
}

#[test]
fn sphere_covers_the_expected_disc_orthographic_and_perspective() {
    let (p, t) = uv_sphere(2.5, 256, 128);
    let black = vec![[0u8; 3]; p.len()];
    for projection in [
        Projection::Orthographic,
        Projection::Perspective { fov_y_deg: 40.0 },
    ] {
        let view = View {
            projection,
            ..Default::default()
        };
        let o = flat_black(view);
        let img = render(&p, &t, &black, None, &o).unwrap();
        let r = view.zoom * 120.0;
        let expected = std::f64::consts::PI * r * r;
        let got = coverage(&img);
        assert!(
            (got / expected - 1.0).abs() < 0.01,
            "{projection:?}: {got} vs {expected}"
        );
    }
}

#[test]
fn shaded_error_colours_are_not_flat_and_deterministic() {
    let (p, t) = uv_sphere(1.0, 400, 200); // 160k triangles: the parallel path
    let colors: Vec<[u8; 3]> = p.iter().map(|q| error_color(0.5 * (q[1] + 1.0))).collect();
    let o = PreviewOptions::default();
    let a = render(&p, &t, &colors, None, &o).unwrap();
    let distinct: std::collections::BTreeSet<_> = a.rgb.chunks(3).collect();
    assert!(distinct.len() > 100, "{} colours", distinct.len());
    assert_eq!(a, render(&p, &t, &colors, None, &o).unwrap());
}

#[test]
fn png_decodes_to_the_requested_size() {
    let (p, t) = uv_sphere(1.0, 32, 16);
    let colors = vec![[10, 200, 30]; p.len()];
    let o = PreviewOptions {
        width: 123,
        height: 77,
        ..Default::default()
    };
    let img = render(&p, &t, &colors, None, &o).unwrap();
    let bytes = img.to_png().unwrap();
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (123, 77));
    assert_eq!(info.color_type, png::ColorType::Rgb);
    assert_eq!(&buf[..info.buffer_size()], &img.rgb[..]);
}

#[test]
fn uniform_colour_shows_in_the_centre_pixel() {
    let (p, t) = uv_sphere(1.0, 64, 32);
    let c = [200, 60, 20];
    let o = PreviewOptions::default();
    let img = render(&p, &t, &vec![c; p.len()], None, &o).unwrap();
    // Headlight: the centre faces the eye, so it is lit fully.
    let got = img.pixel(400, 300);
    for k in 0..3 {
        assert!(got[k].abs_diff(c[k]) <= 3, "{got:?} vs {c:?}");
    }
    assert_eq!(img.pixel(0, 0), o.background);
}

#[test]
fn flipped_faces_are_lit_like_their_neighbours() {
    let (p, mut t) = uv_sphere(1.0, 64, 32);
    for tri in &mut t {
        tri.swap(1, 2);
    }
    let c = [200, 200, 200];
    let img = render(&p, &t, &vec![c; p.len()], None, &PreviewOptions::default()).unwrap();
    assert!(img.pixel(400, 300)[0] >= 197);
}

#[test]
fn bad_input_is_a_typed_error() {
    let o = PreviewOptions::default();
    let (p, t) = uv_sphere(1.0, 8, 4);
    let c = vec![[0u8; 3]; p.len()];
    assert_eq!(
        render(&[], &[], &[], None, &o),
        Err(PreviewError::EmptyMesh {
            vertices: 0,
            triangles: 0
        })
    );
    assert!(matches!(
        render(&p, &[], &c, None, &o),
        Err(PreviewError::EmptyMesh { .. })
    ));
    assert!(matches!(
        render(&p, &t, &c[1..], None, &o),
        Err(PreviewError::ColorCount { .. })
    ));
    let bad = [[0, 1, 999]];
    assert!(matches!(
        render(&p, &bad, &c, None, &o),
        Err(PreviewError::IndexOutOfRange {
            triangle: 0,
            index: 999,
            ..
        })
    ));
    let mut q = p.clone();
    q[3][1] = f64::NAN;
    assert!(matches!(
        render(&q, &t, &c, None, &o),
        Err(PreviewError::NonFinite { vertex: 3, .. })
    ));
    let zero = PreviewOptions {
        width: 0,
        ..o.clone()
    };
    assert!(matches!(
        render(&p, &t, &c, None, &zero),
        Err(PreviewError::BadSize { .. })
    ));
    let wire = Wireframe {
        positions: &p,
        edges: &[[0, 10_000]],
    };
    assert!(matches!(
        render(&p, &t, &c, Some(wire), &o),
        Err(PreviewError::WireIndexOutOfRange { edge: 0, .. })
    ));
}

#[test]
fn wire_on_the_surface_is_drawn_and_behind_it_is_hidden() {
    let (p, t) = uv_sphere(1.0, 64, 32);
    let c = vec![[255u8; 3]; p.len()];
    let view = View {
        azimuth_deg: 0.0,
        elevation_deg: 0.0,
        ..Default::default()
    };
    let o = PreviewOptions {
        view,
        ambient: 1.0,
        ..Default::default()
    };
    let dark = |img: &Image| img.rgb.chunks(3).filter(|c| c[0] < 150).count();
    // A horizontal wire across the front of the sphere (on the surface at its middle)...
    // (chords of 3°, which sag 3.4e-4 below the sphere: within the 1e-2 depth bias).
    let front: Vec<[f64; 3]> = (-10..=10)
        .map(|i| {
            let a = f64::from(i) * 3f64.to_radians();
            [a.sin(), 0.0, a.cos()]
        })
        .collect();
    let edges: Vec<[u32; 2]> = (0..20).map(|i| [i, i + 1]).collect();
    let img = render(
        &p,
        &t,
        &c,
        Some(Wireframe {
            positions: &front,
            edges: &edges,
        }),
        &o,
    )
    .unwrap();
    assert!(dark(&img) > 100, "{}", dark(&img));
    // ...and the same wire at the back is hidden.
    let back: Vec<[f64; 3]> = front.iter().map(|q| [q[0], q[1], -q[2]]).collect();
    let img = render(
        &p,
        &t,
        &c,
        Some(Wireframe {
            positions: &back,
            edges: &edges,
        }),
        &o,
    )
    .unwrap();
    assert_eq!(dark(&img), 0);
}

#[test]
fn colour_bar_sits_on_the_right_and_the_mesh_beside_it() {
    let (p, t) = uv_sphere(1.0, 64, 32);
    let o = PreviewOptions {
        color_bar: Some(ColorBar {
            max: 0.012,
            suffix: "%".into(),
        }),
        ..Default::default()
    };
    let img = render(&p, &t, &vec![[0, 0, 255]; p.len()], None, &o).unwrap();
    let right: Vec<[u8; 3]> = (0..600)
        .flat_map(|y| (640..800).map(move |x| (x, y)))
        .map(|(x, y)| img.pixel(x, y))
        .collect();
    let near = |c: [u8; 3]| {
        right
            .iter()
            .any(|p| (0..3).all(|k| p[k].abs_diff(c[k]) <= 8))
    };
    assert!(near([255, 0, 0]) && near([0, 255, 0]) && near([255, 255, 0]) && near([0, 0, 255]));
    // The sphere is framed in the part left of the bar: its centre pixel is left of 400.
    let row: Vec<u32> = (0..800)
        .filter(|&x| img.pixel(x, 300)[2] > 100 && img.pixel(x, 300)[0] < 50)
        .collect();
    let mid = (row[0] + row[row.len() - 1]) / 2;
    assert!(mid < 380, "{mid}");
}

#[test]
fn quads_are_fan_triangulated() {
    let torus = subfit_mesh::shapes::torus_mesh(1.0, 0.4, 32, 16, false);
    assert!(torus.faces.is_quads());
    let c = vec![[128u8; 3]; torus.positions.len()];
    let img = render_polymesh(&torus, &c, None, &PreviewOptions::default()).unwrap();
    let drawn = img.rgb.chunks(3).filter(|p| p != &[240, 240, 240]).count();
    assert!(drawn > 50_000, "{drawn}");
}

#[test]
fn tiny_images_and_perspective_wires_do_not_panic() {
    let (p, t) = uv_sphere(1.0, 16, 8);
    let c = vec![[90u8; 3]; p.len()];
    let edges: Vec<[u32; 2]> = t.iter().map(|t| [t[0], t[1]]).collect();
    let wire = Wireframe {
        positions: &p,
        edges: &edges,
    };
    for (width, height) in [(1, 1), (2, 3), (17, 5), (5, 40)] {
        for projection in [
            Projection::Orthographic,
            Projection::Perspective { fov_y_deg: 170.0 },
        ] {
            let o = PreviewOptions {
                width,
                height,
                supersample: 3,
                view: View {
                    projection,
                    zoom: 3.0,
                    ..Default::default()
                },
                color_bar: Some(ColorBar {
                    max: 1.0,
                    suffix: "%".into(),
                }),
                ..Default::default()
            };
            let img = render(&p, &t, &c, Some(wire), &o).unwrap();
            assert_eq!(img.rgb.len(), (width * height * 3) as usize);
            img.to_png().unwrap();
        }
    }
}
