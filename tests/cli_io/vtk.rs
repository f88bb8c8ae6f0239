//! `OUTPUT … VTK`: a short run of the pendulum writes a ParaView series whose `.pvd`
//! references existing `.vtu` files with one point per node and one line per beam.

use crate::common;

use mecano::output::vtk::{PVD_NAME, VTK_LINE};

/// The value of attribute `name` in the first tag of `s` that has it.
fn attr<'a>(s: &'a str, name: &str) -> Option<&'a str> {
    let key = format!("{name}=\"");
    let i = s.find(&key)? + key.len();
    let j = s[i..].find('"')?;
    Some(&s[i..i + j])
}

/// The whitespace-separated values of the DataArray whose opening tag contains `marker`.
fn array<'a>(s: &'a str, marker: &str) -> Vec<&'a str> {
    let mut i = s.find(marker).unwrap_or_else(|| panic!("no {marker}"));
    if !marker.contains("Name=") {
        i += s[i..].find("<DataArray").unwrap();
    }
    let open = i + s[i..].find('>').unwrap() + 1;
    let close = open + s[open..].find("</DataArray>").unwrap();
    s[open..close].split_whitespace().collect()
}

#[test]
fn short_pendulum_run_writes_a_readable_paraview_series() {
    let text = std::fs::read_to_string("decks/pendulum.dat").unwrap();
    let text = text
        .replace("END 2.0", "END 0.003")
        .replace("EVERY 10", "EVERY 10 VTK");
    assert!(text.contains(" VTK"));
    let dir = common::TempDir::new("vtk");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let model = mecano::deck::parse_deck(&text, "pendulum_vtk.dat").expect("deck parses");
    assert!(model.output.vtk);
    let report = mecano::app::run_model(&model, "pendulum_vtk.dat", &dir, true)
        .unwrap_or_else(|(c, m)| panic!("run failed ({c}): {m}"));
    assert!(report.failure.is_none());

    let pvd = std::fs::read_to_string(dir.join(PVD_NAME)).unwrap();
    assert!(pvd.contains("type=\"Collection\"") && pvd.trim_end().ends_with("</VTKFile>"));
    let sets: Vec<&str> = pvd.lines().filter(|l| l.contains("<DataSet")).collect();
    // 30 steps, EVERY 10: states 0, 10, 20, 30.
    assert_eq!(sets.len(), 4, "{pvd}");
    let mut last_t = -1.0;
    for line in sets {
        let t: f64 = attr(line, "timestep").unwrap().parse().unwrap();
        assert!(t > last_t);
        last_t = t;
        let file = dir.join(attr(line, "file").unwrap());
        let vtu =
            std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        assert!(
            vtu.contains("type=\"UnstructuredGrid\"") && vtu.trim_end().ends_with("</VTKFile>")
        );
        let n: usize = attr(&vtu, "NumberOfPoints").unwrap().parse().unwrap();
        let m: usize = attr(&vtu, "NumberOfCells").unwrap().parse().unwrap();
        assert_eq!(n, 24, "one point per node");
        assert_eq!(m, 20, "one line per beam element");
        for name in ["displacement", "rotation", "velocity", "angular_velocity"] {
            let v = array(&vtu, &format!("Name=\"{name}\""));
            assert_eq!(v.len(), 3 * n, "{name}");
            assert!(v.iter().all(|x| x.parse::<f64>().is_ok_and(f64::is_finite)));
        }
        let pts = array(&vtu, "<Points>");
        assert_eq!(pts.len(), 3 * n);
        let conn: Vec<usize> = array(&vtu, "Name=\"connectivity\"")
            .iter()
            .map(|x| x.parse().unwrap())
            .collect();
        assert_eq!(conn.len(), 2 * m);
        assert!(conn.iter().all(|&i| i < n));
        let types = array(&vtu, "Name=\"types\"");
        assert!(types.iter().all(|t| *t == VTK_LINE.to_string()));
        assert_eq!(
            array(&vtu, "Name=\"offsets\"").last(),
            Some(&(2 * m).to_string().as_str())
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
