//! Where a superelement's reduced body comes from: an already reduced set in its `FILES`
//! directory ([`super::reduced`]), the reduction cache beside the FE model
//! ([`super::cache`]), or the FE model reduced by this run ([`reduce_fe`]) and then cached.
//! A deck that writes VTK output needs the basis over the mesh for the deformed FE mesh
//! ([`super::mesh`]), which neither the cache nor a reduced set holds: such a run reduces
//! (and still writes the cache), and a reduced set gives no mesh, said in a note.

use super::cache::{self, Lookup, Source};
use super::invariants::Body;
use super::mesh::MeshShape;
use super::{PLACE_TOL, fe, rbe, reduce, reduced};
use crate::elements::BuildError;
use crate::model::{ElementId, Model, SuperelementData};
use nalgebra::{DMatrix, Vector3};

/// A body, its deformed mesh's recovery when the deck writes VTK, and where it came from.
pub type Origin = (Body, Option<MeshShape>, Source);

/// The body of the superelement `id` of data `d` whose model nodes are `nodes` (solver
/// indices: the interface nodes first), its mesh's recovery when the deck writes VTK, and
/// where it came from. Warnings (a cache file that is not valid) and notes (a cache that
/// cannot be written, a reduced set without mesh) go to standard error; none fails the
/// build.
pub fn body_of(
    model: &Model,
    id: ElementId,
    nodes: &[usize],
    d: &SuperelementData,
) -> Result<Origin, BuildError> {
    let invalid = |message: String| BuildError::Invalid {
        element: id,
        message: format!("SUPERELEMENT: {message}"),
    };
    let places: Vec<Vector3<f64>> = (0..d.interface.len())
        .map(|i| model.nodes[nodes[i]].position)
        .collect();
    let what = || format!("element {} (SUPERELEMENT)", id.0);
    let want_mesh = model.output.vtk;
    if reduced::is_set(&d.dir) {
        let body = reduced::read(&d.dir, d, &places).map_err(|e| invalid(e.to_string()))?;
        if want_mesh {
            eprintln!(
                "note: {}: a reduced set holds no mode shapes over the FE mesh: the VTK output has no deformed mesh of it",
                what()
            );
        }
        return Ok((body, None, Source::Reduced(d.dir.clone())));
    }
    let texts = fe::read_texts(&d.dir).map_err(|e| invalid(e.to_string()))?;
    let entry = d.cache.then(|| cache::entry(d, &texts, &places));
    if let Some(e) = entry.as_ref().filter(|_| !want_mesh) {
        match cache::load(e) {
            Lookup::Hit(body) => return Ok((*body, None, Source::Cache(e.path.clone()))),
            Lookup::Miss => {}
            Lookup::Invalid(why) => eprintln!(
                "warning: {}: the reduction cache {} is not valid ({why}): reduced again, and the cache rewritten",
                what(),
                e.path.display()
            ),
        }
    }
    let fe = fe::parse(&d.dir, &texts).map_err(|e| invalid(e.to_string()))?;
    let (body, basis, fe) = reduce_fe(model, nodes, d, fe).map_err(invalid)?;
    // The FE mesh for ParaView, only when the deck asks for VTK output (what a deck does
    // not declare costs nothing: 6 basis rows per FE node).
    let x_f = model.nodes[nodes[0]].position;
    let shape = want_mesh.then(|| MeshShape::new(&fe, &basis, d.interface[0], x_f));
    drop(basis);
    let source = match &entry {
        None => Source::Uncached,
        Some(e) => Source::Computed(match cache::store(e, &body) {
            Ok(()) => Ok(e.path.clone()),
            Err(why) => {
                eprintln!(
                    "note: {}: the reduction is not cached ({why}); the run goes on",
                    what()
                );
                Err(why)
            }
        }),
    };
    Ok((body, shape, source))
}

/// The FE model `fe` of the superelement reduced: its interfaces over many nodes made,
/// its interface nodes checked at their deck places, Craig–Bampton, the invariants; with
/// the basis `Φ` over the FE dofs and the FE model with its RBE interface nodes (what the
/// mesh's recovery reads).
pub fn reduce_fe(
    model: &Model,
    nodes: &[usize],
    d: &SuperelementData,
    fe: fe::FeModel,
) -> Result<(Body, DMatrix<f64>, fe::FeModel), String> {
    // Interfaces over many FE nodes: their nodes at their deck nodes' places.
    let at = |a: u32| {
        let i = d.interface.iter().position(|&b| b == a).unwrap_or(0);
        model.nodes[nodes[i]].position
    };
    let rbes = rbe::resolve_all(&fe, &d.rbe, at).map_err(|e| e.to_string())?;
    let tr = match rbes.is_empty() {
        true => None,
        false => Some(rbe::Transform::new(&fe, &rbes, &d.interface).map_err(|e| e.to_string())?),
    };
    let fe = rbe::with_nodes(fe, &rbes);
    for &a in &d.interface {
        if !fe.nodes.contains_key(&a) {
            return Err(format!(
                "interface node {a}: {} has no node {a}",
                d.dir.join(fe::FILES[2]).display()
            ));
        }
    }
    // Interface places: model and FE agree relative to the frame node.
    let size = fe
        .nodes
        .values()
        .fold(0.0f64, |m, x| m.max((x - fe.nodes[&d.interface[0]]).norm()))
        .max(1e-300);
    let x_f = model.nodes[nodes[0]].position;
    for (i, &a) in d.interface.iter().enumerate().skip(1) {
        let model_rel = model.nodes[nodes[i]].position - x_f;
        let fe_rel = fe.nodes[&a] - fe.nodes[&d.interface[0]];
        if (model_rel - fe_rel).norm() > PLACE_TOL * size {
            return Err(format!(
                "FE interface node {a} ({}) is at {:?} from the frame node in the deck but at {:?} in the FE model",
                model.nodes[nodes[i]].id,
                model_rel.as_slice(),
                fe_rel.as_slice()
            ));
        }
    }
    let (body, basis) = match tr.as_ref() {
        // Interfaces over many nodes: the reduction on TᵀKT, TᵀMT.
        Some(tr) => rbe::reduce_body_and_basis(&fe, tr, &d.interface, d.modes as usize),
        None => reduce::reduce_body_and_basis(&fe, &d.interface, d.modes as usize),
    }?;
    Ok((body, basis, fe))
}
