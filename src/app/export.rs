//! `mecano-rs export DECK`: the linear stiffness and mass of a deck's structure at its
//! reference state, as the files a `SUPERELEMENT` reads (issue 38 §5): `K.mtx`, `M.mtx`
//! (Matrix Market, coordinate real symmetric), `nodes.csv`, `dofs.csv`
//! (`crate::elements::superelement::fe`). The matrices are the project's own linearisation
//! ([`crate::modes::linearise`]) about the reference configuration at rest: `K = ∂r/∂q`
//! (material stiffness: no stress, no velocity at rest), `M = ∂r/∂a`, on every nodal
//! unknown that is not fixed (`FIX` in `NODES` removes the dof). Constraint equations
//! (joints, drivers) are not part of a structure's `K` and `M`: a deck with them is
//! refused rather than exported without them.

use crate::app::{self, EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK};
use crate::elements::NodeState;
use crate::elements::superelement::{fe, mtx::SymMatrix};
use crate::solver::system::FIXED;
use clap::Args;
use std::path::PathBuf;

/// Options of `mecano-rs export`.
#[derive(Args, Debug, Clone)]
pub struct ExportArgs {
    /// The input deck (a structure: beams, masses, springs; no joints).
    pub deck: PathBuf,
    /// Output directory (default: out/<deck name>/export).
    #[arg(short = 'o', long = "out", value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Divide every BEAM into K times its elements (as for runs).
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub refine: u32,
    /// Override a deck parameter: `--set E=2.1e10`; repeatable.
    #[arg(long = "set", value_name = "NAME=VALUE", value_parser = app::SetParser)]
    pub set: Vec<(String, f64)>,
    /// Write into a directory that holds files no mecano-rs run wrote there.
    #[arg(long)]
    pub force: bool,
    /// Nothing on standard output.
    #[arg(short, long)]
    pub quiet: bool,
    /// Write instead the reduced set of the deck's SUPERELEMENT of this number (its
    /// reduction, as the files an already reduced SUPERELEMENT reads: docs/superelements.md).
    #[arg(long, value_name = "ELEMENT")]
    pub reduced: Option<u32>,
}

/// Largest number of nodal unknowns exported (the linearisation is dense).
pub const MAX_UNKNOWNS: usize = 4000;

/// Relative size below which an assembled entry is round-off and not written.
const DROP: f64 = 1e-14;

/// `mecano-rs export`: returns the exit code.
pub fn run(args: &ExportArgs) -> u8 {
    let (model, _) = match app::load_source(&args.deck, &args.set, args.refine) {
        Ok(m) => m,
        Err(code) => return code,
    };
    let deck = args.deck.display();
    if let Some(id) = args.reduced {
        return export_reduced(args, &model, id);
    }
    let integ = match crate::solver::prepare(&model) {
        Ok(i) => i,
        Err(e) => {
            eprintln!(
                "error: {}",
                app::locate::located_model_error(&args.deck, &model, &e)
            );
            return EXIT_BAD_INPUT;
        }
    };
    let sys = &integ.sys;
    let nn = sys.n_node_eq;
    if sys.n_eq() > nn {
        eprintln!(
            "error: {deck}: the deck has {} constraint equations (joints, drivers, RIGID, PRESCRIBED): export writes a structure's K and M, which do not hold them; remove them (fix dofs with FIX in NODES)",
            sys.n_eq() - nn
        );
        return EXIT_BAD_INPUT;
    }
    if nn > MAX_UNKNOWNS {
        eprintln!(
            "error: {deck}: {nn} unknowns: export linearises densely, at most {MAX_UNKNOWNS}"
        );
        return EXIT_BAD_INPUT;
    }
    // The reference configuration at rest.
    let nodes: Vec<NodeState> = model
        .nodes
        .values()
        .map(|n| NodeState::at_rest(n.position))
        .collect();
    let lin =
        crate::modes::linearise::linearise(sys, &nodes, &vec![0.0; sys.n_eq()], integ.scale, 0.0);
    let sym = |a: &nalgebra::DMatrix<f64>| (a + a.transpose()) * 0.5;
    let asym = |a: &nalgebra::DMatrix<f64>| {
        let max = a.amax().max(1e-300);
        (a - a.transpose()).amax() / max
    };
    let (ak, am) = (asym(&lin.k), asym(&lin.m));
    // Nodal equation → (node number, component).
    let mut dofs = vec![(0u32, 0u8); nn];
    let mut used = vec![false; model.nodes.len()];
    for (i, d) in sys.node_dofs.iter().enumerate() {
        for (c, &e) in d.iter().enumerate() {
            if e != FIXED && e < nn {
                dofs[e] = (model.nodes[i].id.0, c as u8);
                used[i] = true;
            }
        }
    }
    let coords: Vec<(u32, nalgebra::Vector3<f64>)> = model
        .nodes
        .values()
        .zip(&used)
        .filter(|(_, u)| **u)
        .map(|(n, _)| (n.id.0, n.position))
        .collect();
    let comment = format!(
        "mecano-rs export of {deck}: linearised at the reference state at rest; rows: dofs.csv"
    );
    let texts = [
        SymMatrix::from_dense(&sym(&lin.k), DROP)
            .to_text(&format!("stiffness K, N/m, N, N·m. {comment}")),
        SymMatrix::from_dense(&sym(&lin.m), DROP)
            .to_text(&format!("mass M, kg, kg·m, kg·m². {comment}")),
        fe::nodes_text(&coords),
        fe::dofs_text(&dofs),
    ];
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| app::default_out_dir(&args.deck, &model).join("export"));
    let files: Vec<String> = fe::FILES.iter().map(|s| s.to_string()).collect();
    let _claim = match app::outdir::OutDir::claim_fresh(&dir, &files, args.force) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {deck}: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    for (name, text) in fe::FILES.iter().zip(&texts) {
        if let Err(e) = crate::safe_file::write(&dir.join(name), text.as_bytes()) {
            eprintln!("error: writing {}: {e}", dir.join(name).display());
            return EXIT_FAILED;
        }
    }
    if !args.quiet {
        println!(
            "{nn} dofs on {} nodes; asymmetry of K {ak:.1e}, of M {am:.1e} (symmetrised)\nwritten: {}",
            coords.len(),
            dir.display()
        );
    }
    EXIT_OK
}

/// `mecano-rs export DECK --reduced ID`: the reduced set of SUPERELEMENT `ID`
/// (`crate::elements::superelement::reduced`), reduced as a run would (or read from its
/// cache).
fn export_reduced(args: &ExportArgs, model: &crate::model::Model, id: u32) -> u8 {
    use crate::elements::superelement::{Superelement, reduced};
    let deck = args.deck.display();
    let Some((el, d)) = model
        .elements
        .get(&crate::model::ElementId(id))
        .and_then(|e| match &e.kind {
            crate::model::ElementKind::Superelement(d) => Some((e, d)),
            _ => None,
        })
    else {
        eprintln!("error: {deck}: --reduced {id}: the deck has no SUPERELEMENT {id}");
        return EXIT_BAD_INPUT;
    };
    let nodes: Vec<usize> = el
        .nodes
        .iter()
        .map(|n| model.nodes.get_index_of(n).expect("validated model"))
        .collect();
    let se = match Superelement::from_model(model, el.id, nodes, d) {
        Ok(s) => s,
        Err(e) => {
            let e = crate::solver::BuildError::Elements(e);
            eprintln!(
                "error: {}",
                app::locate::located_model_error(&args.deck, model, &e)
            );
            return EXIT_BAD_INPUT;
        }
    };
    let about = format!("mecano-rs export --reduced {id} of {deck}");
    let texts = reduced::texts(se.body(), &d.interface, &about);
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| app::default_out_dir(&args.deck, model).join("reduced"));
    let files: Vec<String> = reduced::FILES.iter().map(|s| s.to_string()).collect();
    let _claim = match app::outdir::OutDir::claim_fresh(&dir, &files, args.force) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {deck}: {e}");
            return EXIT_BAD_INPUT;
        }
    };
    for (name, text) in reduced::FILES.iter().zip(&texts) {
        if let Err(e) = crate::safe_file::write(&dir.join(name), text.as_bytes()) {
            eprintln!("error: writing {}: {e}", dir.join(name).display());
            return EXIT_FAILED;
        }
    }
    if !args.quiet {
        println!(
            "SUPERELEMENT {id}: {} elastic coordinates, {} kg\nwritten: {}",
            se.body().n,
            se.body().mass,
            dir.display()
        );
    }
    EXIT_OK
}
