use super::*;

fn plan(text: &str) -> Result<Plan, SweepError> {
    Plan::parse(text, Path::new("sweeps/p.toml"), None)
}

#[test]
fn inverse_normal_matches_known_quantiles() {
    // Φ⁻¹ at 0.5, 0.975, 0.8413447460685429 (Φ(1)), 1e-6 (tables: −4.753424308822899).
    assert_eq!(inverse_normal_cdf(0.5), 0.0);
    assert!((inverse_normal_cdf(0.975) - 1.959963984540054).abs() < 1.15e-9 * 1.96);
    assert!((inverse_normal_cdf(0.8413447460685429) - 1.0).abs() < 2e-9);
    assert!((inverse_normal_cdf(1e-6) + 4.753424308822899).abs() < 1.15e-9 * 4.76);
    assert!((inverse_normal_cdf(1.0 - 0.975) + 1.959963984540054).abs() < 3e-9);
}

#[test]
fn grids_factorial_zip_and_ranges() {
    let p = plan("deck = \"d.dat\"\n[[parameter]]\nname = \"a\"\nvalues = [1, 2]\n[[parameter]]\nname = \"b\"\nfrom = 1\nto = 100\nn = 3\nscale = \"log\"\n").expect("valid");
    assert_eq!(p.deck, PathBuf::from("sweeps/d.dat"));
    assert_eq!(p.out, PathBuf::from("out/sweeps/p"));
    assert_eq!(p.cases.len(), 6);
    assert_eq!(p.cases[0], [1.0, 1.0]);
    assert!((p.cases[1][1] - 10.0).abs() < 1e-12);
    assert_eq!(p.cases[2], [1.0, 100.0]);
    assert_eq!(p.cases[3], [2.0, 1.0]);
    assert_eq!(p.case_dir(3), PathBuf::from("out/sweeps/p/cases/0003"));
    let z = plan("deck = \"d.dat\"\ncombine = \"zip\"\n[[parameter]]\nname = \"a\"\nvalues = [1, 2]\n[[parameter]]\nname = \"b\"\nfrom = 0\nto = 1\nn = 2\n").expect("valid");
    assert_eq!(z.cases, vec![vec![1.0, 0.0], vec![2.0, 1.0]]);
    assert_eq!(z.one_dimensional(), None);
    let bad = plan(
        "deck = \"d.dat\"\ncombine = \"zip\"\n[[parameter]]\nname = \"a\"\nvalues = [1, 2]\n[[parameter]]\nname = \"b\"\nvalues = [1]\n",
    );
    assert!(bad.is_err());
}

#[test]
fn random_draws_are_reproducible_and_stratified() {
    let text = "deck = \"d.dat\"\nsamples = 100\nseed = 7\nsampling = \"latin-hypercube\"\n\
            [[parameter]]\nname = \"k\"\ndistribution = \"uniform\"\nlow = 0\nhigh = 1\n\
            [[parameter]]\nname = \"E\"\ndistribution = \"lognormal\"\nmedian = 2\nsigma = 0.05\n";
    let a = plan(text).expect("valid");
    let b = plan(text).expect("valid");
    assert_eq!(a.cases, b.cases, "same plan, same cases");
    // Latin hypercube: exactly one k in each of the 100 strata [i/100, (i+1)/100).
    let mut strata: Vec<usize> = a.cases.iter().map(|c| (c[0] * 100.0) as usize).collect();
    strata.sort_unstable();
    assert_eq!(strata, (0..100).collect::<Vec<_>>());
    // ln E: one value per normal stratum, so its sample mean is ln 2 within a few
    // 1e-4 (the stratified mean's error is far below the MC error sigma/10 = 5e-3).
    let m = a.cases.iter().map(|c| c[1].ln()).sum::<f64>() / 100.0;
    assert!((m - 2f64.ln()).abs() < 1e-3, "{m}");
    let other = plan(&text.replace("seed = 7", "seed = 8")).expect("valid");
    assert_ne!(a.cases, other.cases);
    let mc = plan(&text.replace("latin-hypercube", "monte-carlo")).expect("valid");
    assert!(
        mc.cases
            .iter()
            .all(|c| (0.0..1.0).contains(&c[0]) && c[1] > 0.0)
    );
}

#[test]
fn mistakes_are_reported() {
    for (text, needle) in [
        ("deck = \"d.dat\"\n", "no [[parameter]]"),
        (
            "deck = \"d.dat\"\n[[parameter]]\nname = \"a\"\n",
            "exactly one",
        ),
        (
            "deck = \"d.dat\"\n[[parameter]]\nname = \"a\"\ndistribution = \"uniform\"\nlow = 1\nhigh = 2\n",
            "samples",
        ),
        (
            "deck = \"d.dat\"\nsamples = 3\n[[parameter]]\nname = \"a\"\ndistribution = \"uniform\"\nlow = 1\nhigh = 2\n",
            "seed",
        ),
        (
            "deck = \"d.dat\"\n[[parameter]]\nname = \"a\"\nfrom = -1\nto = 2\nn = 3\nscale = \"log\"\n",
            "logarithmic",
        ),
        ("deck = \"d.dat\"\nbogus = 1\n", "bogus"),
        (
            "deck = \"d.dat\"\n[[parameter]]\nname = \"a\"\nvalues = [1]\n[[parameter]]\nname = \"a\"\nvalues = [2]\n",
            "twice",
        ),
    ] {
        let e = plan(text).expect_err(text).to_string();
        assert!(e.contains(needle), "{text}: {e}");
    }
}
