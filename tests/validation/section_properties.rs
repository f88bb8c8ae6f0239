//! Sections given by their properties per unit length (`PROPERTIES`, issue 25 §4): the same
//! results as the material and geometry they equal, a rotary inertia no material can give,
//! the canonical writer, and bad input.

use crate::common;

use mecano::app::modes::{About, analyse_model};
use mecano::deck::{load_deck, parse_deck, strip_spans, write_deck};
use mecano::model::{BeamProperties, ElementKind, Model, Section, SectionData, SectionId};
use mecano::output::History;
use nalgebra::Vector3;
use std::f64::consts::PI;
use std::path::Path;

fn deck(name: &str) -> Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("decks")
        .join(name);
    load_deck(&path).unwrap_or_else(|e| panic!("{name}: {:?}", miette::Report::new(e)))
}

/// The model with every beam's material and geometric section replaced by one section of
/// properties per (material, section) pair, its values computed here from E, G, ρ and
/// A, I₂, I₃, J, k as grammar.md states them (EA = E·A, GA₂ = GA₃ = k·G·A, GJ = G·J,
/// EI₂ = E·I₂, EI₃ = E·I₃, ρA = ρ·A, ρJ = ρ(I₂ + I₃), ρI₂ = ρ·I₂, ρI₃ = ρ·I₃; the same
/// operations in the same order as the library's, so the doubles are the same), the
/// material's DAMPING on the section. The new sections are numbered from 1000.
fn as_properties(mut m: Model) -> Model {
    let mut made: Vec<((u32, u32), SectionId)> = Vec::new();
    let mut new_sections = Vec::new();
    for el in m.elements.values_mut() {
        let ElementKind::Beam {
            material, section, ..
        } = &mut el.kind
        else {
            continue;
        };
        let mid = material.take().expect("the deck's beams name a material");
        let key = (mid.0, section.0);
        if let Some((_, id)) = made.iter().find(|(k, _)| *k == key) {
            *section = *id;
            continue;
        }
        let mat = &m.materials[&mid];
        let sec = &m.sections[&*section];
        let g = *sec.geometry().expect("a geometric section");
        let (e, gs, rho) = (mat.young, mat.shear, mat.density);
        let props = BeamProperties {
            cn: Vector3::new(
                e * g.area,
                g.shear_factor * gs * g.area,
                g.shear_factor * gs * g.area,
            ),
            cm: Vector3::new(gs * g.torsion, e * g.i2, e * g.i3),
            mass: rho * g.area,
            inertia: Vector3::new((g.i2 + g.i3) * rho, g.i2 * rho, g.i3 * rho),
        };
        let id = SectionId(1000 + made.len() as u32);
        let damping = if sec.rigid { 0.0 } else { mat.damping };
        new_sections.push(Section {
            id,
            data: SectionData::Properties { props, damping },
            rigid: sec.rigid,
            span: Default::default(),
        });
        made.push((key, id));
        *section = id;
    }
    for s in new_sections {
        m.sections.insert(s.id, s);
    }
    m
}

/// Runs `m` and returns its recorded history.
fn history(m: &Model) -> History {
    let mut h = History::new(1);
    let report = mecano::solver::run(m, &mut h).expect("the run starts");
    assert!(report.failure.is_none(), "{:?}", report.failure);
    h
}

/// The model of material and geometry and the one of properties (written by the
/// canonical writer and read back, so the writer and the parser are on the path) give the
/// same history bit for bit: same positions, rotations, velocities and energies at every
/// step. Equality, not a tolerance: the element is given the same doubles.
fn same_history(name: &str, m: Model) {
    let converted = as_properties(m.clone());
    let text = write_deck(&converted);
    assert!(
        text.contains("PROPERTIES") && !text.contains(" MAT "),
        "{text}"
    );
    let reread = parse_deck(&text, "written").unwrap_or_else(|e| {
        panic!("{name}: {:?}\n{text}", miette::Report::new(e));
    });
    let (a, b) = (history(&m), history(&reread));
    assert_eq!(a.t, b.t, "{name}: times");
    assert!(a.nodes.len() > 5, "{name}: a few steps at least");
    for (k, (sa, sb)) in a.nodes.iter().zip(&b.nodes).enumerate() {
        for (na, nb) in sa.iter().zip(sb) {
            assert!(
                na.x == nb.x && na.r == nb.r && na.v == nb.v && na.w == nb.w,
                "{name}: state {k} differs: {na:?} vs {nb:?}"
            );
        }
    }
    assert_eq!(a.energy, b.energy, "{name}: energies");
    assert_eq!(a.damping_work, b.damping_work, "{name}: damping work");
    eprintln!("{name}: {} states identical", a.nodes.len());
}

/// Cuts a dynamic analysis to `steps` of its step.
fn cut(mut m: Model, steps: f64) -> Model {
    if let mecano::model::Analysis::Dynamic { step, .. } = m.analysis {
        assert!(m.set_fixed_step(step, steps * step, None));
    }
    m
}

#[test]
fn properties_equal_to_a_material_and_geometry_give_bit_identical_runs() {
    // Two-node beams (the undamped fast path), dynamic.
    let m = cut(deck("cantilever_smooth_load.dat"), 40.0);
    same_history("two-node beams", m.clone());
    // With DAMPING: the order-1 damped element, the damping read from the section.
    let mut damped = m;
    damped.materials.values_mut().for_each(|x| x.damping = 2e-4);
    same_history("two-node beams, DAMPING 2e-4", damped);
    // Beams of order 11, static (every load step compared).
    same_history("order 11", deck("cantilever_rollup_p11.dat"));
    // RIGID sections: the bars' inertia (ρA, ρJ = ρ(I₂+I₃), ρI₂, ρI₃) only.
    let mut rigid = cut(deck("double_pendulum_beams.dat"), 40.0);
    rigid.sections.values_mut().for_each(|s| s.rigid = true);
    same_history("rigid sections", rigid);
}

/// A free–free bar in torsion with ρJ = 0.7 kg·m and ρI₂ = ρI₃ = 0.1 kg·m: no material
/// gives ρJ ≠ ρI₂ + ρI₃ (a material's polar rotary inertia is ρ(I₂ + I₃)). Torsion is the
/// wave equation GJ θ'' = ρJ θ̈ with free ends: ω_k = (kπ/L) √(GJ/ρJ). The bar is stiff in
/// bending and tension (first bending frequency 22.37/L² √(EI/ρA) = 559 rad/s against
/// 3.25 rad/s), so modes 7, 8, 9 (after six rigid ones) are the torsion modes k = 1, 2, 3.
fn torsion_bar(beam: &str) -> String {
    format!(
        "SECTIONS
  1 PROPERTIES EA 1e6 GA2 1e6 GA3 1e6 GJ 3 EI2 1e4 EI3 1e4 RHOA 1 RHOJ 0.7 RHOI2 0.1 RHOI3 0.1
NODES
  1 0 0 0
  2 2 0 0
ELEMENTS
  1 BEAM 1 2 SEC 1 {beam}
ANALYSIS MODES 9
"
    )
}

const GJ: f64 = 3.0;
const RHO_J: f64 = 0.7;
const L: f64 = 2.0;

fn torsion_frequencies(beam: &str) -> Vec<f64> {
    let model = parse_deck(&torsion_bar(beam), "torsion.dat").expect("valid deck");
    let a = analyse_model(&model, About::Initial, 9)
        .map_err(|f| f.message)
        .expect("modal analysis")
        .1;
    assert_eq!(a.rigid_modes, 6);
    a.modes[6..9]
        .iter()
        .map(|m| 2.0 * PI * m.natural_hz)
        .collect()
}

#[test]
fn torsional_frequencies_of_a_free_free_bar_follow_rho_j() {
    let c = (GJ / RHO_J).sqrt();
    // n two-node beams: torsion stiffness GJ/Lₑ per element (exact for the linear
    // element), rotary inertia ρJ Lₑ/2 lumped at each of its nodes: the free–free chain of
    // n springs, whose frequencies are exactly ω_k = (2n/L) c sin(kπ/(2n)). Tolerance: the
    // eigensolver's round-off, 1e-9 relative.
    let n = 20.0;
    let w = torsion_frequencies("DIVIDE 20");
    for (k, wk) in w.iter().enumerate() {
        let k = (k + 1) as f64;
        let x = k * PI / (2.0 * n);
        let chain = 2.0 * n / L * c * x.sin();
        let continuum = k * PI / L * c;
        eprintln!("two-node, k = {k}: {wk} rad/s; chain {chain}, continuum {continuum}");
        assert!((wk / chain - 1.0).abs() < 1e-9, "k = {k}: {wk} vs {chain}");
        // And so below the continuum by sin x / x − 1 = −x²/6 + x⁴/120 − …
        let rel = wk / continuum - 1.0;
        assert!(
            (rel + x * x / 6.0).abs() <= x.powi(4) / 120.0 + 1e-9,
            "{rel}"
        );
    }
    // Two beams of order 8 (the order-p element: rotary inertia lumped at the
    // Gauss–Lobatto points with their weights, the spectral-element scheme, whose error
    // for 5+ nodes per half wave is below 1e-6 here; a material's ρ(I₂ + I₃) = 0.2 in place
    // of ρJ = 0.7 would be 87 % off).
    let w = torsion_frequencies("ORDER 8 DIVIDE 2");
    for (k, wk) in w.iter().enumerate() {
        let k = (k + 1) as f64;
        let continuum = k * PI / L * c;
        eprintln!("order 8, k = {k}: {wk} rad/s; continuum {continuum}");
        assert!((wk / continuum - 1.0).abs() < 1e-6, "k = {k}: {wk}");
    }
}

/// A rigid bar of properties: its own ρJ about its axis. A free RIGID bar turning about
/// its axis at W has kinetic energy ½ ρJ L W² (and no strain energy).
#[test]
fn a_rigid_section_of_properties_carries_its_polar_inertia() {
    let text = "SECTIONS
  1 RIGID PROPERTIES RHOA 2 RHOJ 0.3
NODES
  1 0 0 0
  2 1.5 0 0
ELEMENTS
  1 BEAM 1 2 SEC 1
INITIAL
  1 TO 2 W 4 0 0
ANALYSIS DYNAMIC ALPHA 0 STEP 1e-3 END 5e-3
";
    let m = parse_deck(text, "rigid.dat").expect("valid deck");
    let h = history(&m);
    // ½ ρJ L W² = ½ · 0.3 · 1.5 · 16 = 3.6 J, to round-off (no other motion).
    for e in &h.energy {
        assert!((e - 3.6).abs() < 1e-12 * 3.6, "{e}");
    }
}

/// Bad input: located errors, exit 2, nothing written.
#[test]
fn bad_sections_of_properties_are_located_errors() {
    const P: &str = "EA 1 GA2 1 GA3 1 GJ 1 EI2 1 EI3 1 RHOA 1 RHOJ 1 RHOI2 1";
    const N: &str = "NODES\n 1 0 0 0\n 2 1 0 0\n";
    const A: &str = "ANALYSIS STATIC\n";
    let cases: Vec<(String, usize, usize, &str)> = vec![
        // a property missing: reported at the card's end
        (
            format!("SECTIONS\n 1 PROPERTIES {P}\n{A}"),
            2,
            70,
            "section 1 needs RHOI3 <value>",
        ),
        // not positive
        (
            format!("SECTIONS\n 1 PROPERTIES EA 0 GA2 1\n{A}"),
            2,
            18,
            "EA = 0 is out of range: expected > 0 N",
        ),
        (
            format!("SECTIONS\n 1 PROPERTIES EA 1 GA2 -1\n{A}"),
            2,
            24,
            "GA2 = -1 is out of range",
        ),
        (
            format!("SECTIONS\n 1 PROPERTIES {P} RHOI3 -0.5\n{A}"),
            2,
            77,
            "RHOI3 = -0.5 is out of range: expected >= 0 kg·m",
        ),
        // twice
        (
            format!("SECTIONS\n 1 PROPERTIES {P} RHOI3 1 EI3 2\n{A}"),
            2,
            79,
            "`EI3` given twice",
        ),
        // a rigid section has no stiffness, and no damping
        (
            format!("SECTIONS\n 1 RIGID PROPERTIES RHOA 1 EA 3\n{A}"),
            2,
            28,
            "one of RHOA, RHOJ, RHOI2, RHOI3",
        ),
        (
            format!("SECTIONS\n 1 RIGID PROPERTIES RHOJ 1\n{A}"),
            2,
            27,
            "section 1 needs RHOA <value>",
        ),
        // geometry and properties do not mix
        (
            format!("SECTIONS\n 1 PROPERTIES A 1\n{A}"),
            2,
            15,
            "unexpected `A` in section 1: expected one of EA,",
        ),
        // a BEAM of a section of properties names no material
        (
            format!(
                "MATERIALS\n 1 E 1 NU 0.3 RHO 1\nSECTIONS\n 1 PROPERTIES {P} RHOI3 1\n{N}ELEMENTS\n 1 BEAM 1 2 MAT 1 SEC 1\n{A}"
            ),
            9,
            17,
            "remove MAT",
        ),
        // and a BEAM of a geometric section still needs one
        (
            format!("SECTIONS\n 1 A 1 I2 1 I3 1 J 1\n{N}ELEMENTS\n 1 BEAM 1 2 SEC 1\n{A}"),
            7,
            18,
            "needs MAT <material number>",
        ),
    ];
    let mut failures = Vec::new();
    for (text, line, col, gist) in &cases {
        let errs = match parse_deck(text, "bad.dat") {
            Ok(_) => panic!("accepted:\n{text}"),
            Err(e) => e,
        };
        let msg = errs.errors()[0].to_string();
        let at = errs.line_col(0);
        if at != Some((*line, *col)) || !msg.contains(gist) {
            failures.push(format!(
                "{text:?}\n  expected {line}:{col} {gist:?}\n  got {at:?} {msg:?}"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // Through the binary: exit 2 and nothing written.
    let dir = common::TempDir::new("section_properties_bad");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("bad.dat");
    std::fs::write(&path, &cases[0].0).expect("deck written");
    let out = dir.join("out");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_mecano-rs"))
        .arg(&path)
        .arg("-q")
        .arg("-o")
        .arg(&out)
        .output()
        .expect("mecano-rs runs");
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("RHOI3"));
    assert!(!out.exists(), "nothing written");
}

/// The canonical writer prints every form of section so that it reads back the same.
#[test]
fn sections_of_properties_round_trip() {
    let text = "SECTIONS
  1 PROPERTIES EA 1e6 GA2 2e6 GA3 3e6 GJ 4e3 EI2 5e3 EI3 6e3 RHOA 1 RHOJ 20 RHOI2 10 RHOI3 11 DAMPING 1e-3
  2 RIGID PROPERTIES RHOA 5
  3 RIGID PROPERTIES RHOA 5 RHOI3 0.25 RHOJ 0.5 RHOI2 0.25
NODES
  1 0 0 0 FIX ALL
  2 1 0 0
  3 2 0 0
ELEMENTS
  1 BEAM 1 2 SEC 1 DIVIDE 3
  2 BEAM 2 3 SEC 3 ORDER 2
ANALYSIS STATIC
";
    let mut first = parse_deck(text, "a.dat").expect("valid deck");
    let written = write_deck(&first);
    let mut second = parse_deck(&written, "b.dat").expect("the written deck reads");
    strip_spans(&mut first);
    strip_spans(&mut second);
    assert_eq!(first, second, "{written}");
    assert_eq!(write_deck(&second), written);
    let s = &first.sections[&SectionId(1)];
    let SectionData::Properties { props, damping } = s.data else {
        panic!("{s:?}")
    };
    assert_eq!(
        (props.cn, props.cm, props.mass, props.inertia, damping),
        (
            Vector3::new(1e6, 2e6, 3e6),
            Vector3::new(4e3, 5e3, 6e3),
            1.0,
            Vector3::new(20.0, 10.0, 11.0),
            1e-3
        )
    );
    // Rigid: the rotary inertias default to 0; no stiffness.
    let SectionData::Properties { props, .. } = first.sections[&SectionId(2)].data else {
        panic!()
    };
    assert_eq!(
        (props.cn, props.inertia),
        (Vector3::zeros(), Vector3::zeros())
    );
}
