//! Real environment maps from `$TRILUX_DATA/hdr` (ignored, and listed as
//! such, when the variable is unset; see `build.rs`).

use discrete_sampling::{CdfBisection, DiscreteSampler, Distribution2D, GuideTable};
use rand::SeedableRng;
use rand::distr::Distribution;
use rand_pcg::Pcg64Mcg;

use crate::hdr::{hdr_files, load_luminance};
use crate::stats::chi_square;

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn hdr_environment_maps() {
    let files = hdr_files().expect("TRILUX_DATA must name the data folder for this test");
    assert!(
        files.len() >= 2,
        "expected the two HDR maps of the data README"
    );
    for path in files {
        let lum = load_luminance(&path).unwrap();
        let (w, h) = (lum.width, lum.height);
        assert_eq!((w, h), (1024, 512), "{}", lum.name);

        // 1D over all texels: the guide table is the same inversion as bisection.
        let g = GuideTable::new(&lum.values).unwrap();
        let b = CdfBisection::new(&lum.values).unwrap();
        for j in 0..200_000 {
            let u = (j as f64 + 0.37) / 200_000.0;
            assert_eq!(g.sample_u(u), b.sample_u(u), "{} at u = {u}", lum.name);
        }

        // 2D lat-long: the brightest texel has the largest cell probability
        // among its row, and 10⁶ samples binned into 32×16 blocks match the
        // exact block masses.
        let d = Distribution2D::from_equirect(&lum.values, w, h).unwrap();
        let brightest = (0..w * h)
            .max_by(|&a, &b| lum.values[a].total_cmp(&lum.values[b]))
            .unwrap();
        let (bx, by) = (brightest % w, brightest / w);
        if lum.name.starts_with("spiaggia") {
            assert_eq!((by, bx), (184, 615), "the sun of the data README");
        }
        let row = d.row(by).unwrap();
        assert!((0..w).all(|x| row.pdf(x) <= row.pdf(bx)));

        let (bw, bh) = (32, 16);
        let mut exact = vec![0.0f64; bw * bh];
        for y in 0..h {
            for x in 0..w {
                exact[(y * bh / h) * bw + x * bw / w] += d.cell_probability([x, y]);
            }
        }
        let mut counts = vec![0u64; bw * bh];
        let mut rng = Pcg64Mcg::seed_from_u64(77);
        for _ in 0..1_000_000 {
            let s = d.sample(&mut rng);
            counts[(s.cell[1] * bh / h) * bw + s.cell[0] * bw / w] += 1;
        }
        let test = chi_square(&counts, &exact, 20.0);
        assert!(
            test.p_value > 1e-3,
            "{}: p = {:.2e}",
            lum.name,
            test.p_value
        );
    }
}

/// The README's file-to-result path on a real map: read, build, sample a
/// direction, evaluate the density of another.
#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn readme_sky_example_on_a_real_map() {
    let dir = crate::hdr::data_dir().expect("TRILUX_DATA must name the data folder");
    let path = dir.join("hdr/kloppenheim_06_1k.hdr");
    let map = trilux_io::image::read(&path).unwrap();
    let env =
        Distribution2D::from_equirect(&map.luminance(), map.width as usize, map.height as usize)
            .unwrap();
    let light = env.sample_direction([0.3, 0.6]);
    let len: f64 = light.direction.iter().map(|c| c * c).sum::<f64>().sqrt();
    assert!((len - 1.0).abs() < 1e-12 && light.pdf > 0.0);
    assert!((env.pdf_direction(light.direction) - light.pdf).abs() < 1e-9 * light.pdf);
    assert!(env.pdf_direction([0.0, 0.0, 1.0]) >= 0.0);
    // The same luminance as this crate's own function.
    let p = map.pixels[12345];
    let ours = discrete_sampling::luminance([p[0], p[1], p[2]]);
    assert!((map.luminance()[12345] - ours).abs() <= 1e-6 * ours.max(1.0));
}
