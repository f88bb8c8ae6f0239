//! Stage 2, LOADS, INITIAL, ANALYSIS and OUTPUT.

use super::cursor::*;
use super::*;
use crate::model::{Carry, Scheme};

/// Most Newton iterations a step may take (`MAXIT`).
pub const MAX_NEWTON_ITERATIONS: u32 = 1000;
/// Largest ratio of the end time to the smallest step: 1e12 keeps `t + 1e-3·MINSTEP > t`
/// at `t = END` with a margin of 4 (2⁻⁵² · 1e15 ≈ 0.22).
pub const MAX_END_OVER_MINSTEP: f64 = 1e12;

impl Builder<'_> {
    // ---------------------------------------------------------------- LOADS
    pub(super) fn load(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "LOADS card");
        let (kw, ks) =
            c.expect_keyword(&["GRAVITY", "FORCE", "MOMENT"], "GRAVITY, FORCE or MOMENT")?;
        c.ctx = kw.to_string();
        if kw == "GRAVITY" {
            let (g, _, _) = c.vec3("GRAVITY")?;
            c.finish()?;
            if let Some((_, first)) = self.gravity {
                let first_line = self.line(first);
                return Err(DeckError::new(
                    K::RepeatedCard {
                        keyword: "GRAVITY".into(),
                        first_line,
                    },
                    ks,
                ));
            }
            self.gravity = Some((g, span));
            return Ok(());
        }
        let (n, ns) = c.uint("node number")?;
        let (value, _, _) = c.vec3(kw)?;
        let mut function = None;
        if c.keyword(&["FUNCTION"]).is_some() {
            let (f, fs) = c.uint("function number")?;
            function = Some(self.function_ref(f, fs)?);
        }
        c.finish()?;
        let node = self.node_ref(n, ns)?;
        self.loads.push(NodalLoad {
            node,
            moment: kw == "MOMENT",
            value,
            function,
            span,
        });
        Ok(())
    }

    // ---------------------------------------------------------------- INITIAL
    /// `<n> [TO <n2>] [V vx vy vz] [W wx wy wz] [ABOUT cx cy cz]`: with ABOUT, each node
    /// gets the rigid-body velocity `V + W × (x − c)`.
    pub(super) fn initial(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "INITIAL card");
        let (first, fs) = c.uint("node number")?;
        let mut last = first;
        let mut last_span = fs;
        if c.keyword(&["TO"]).is_some() {
            (last, last_span) = c.uint("last node number")?;
            if last < first {
                return Err(DeckError::new(
                    K::BadGeneration {
                        first,
                        last,
                        reason: "the last number must not be smaller than the first".into(),
                    },
                    Span::new(fs.start, last_span.end),
                ));
            }
            generation_size(first, last, Span::new(fs.start, last_span.end))?;
        }
        let mut v = Vector3::zeros();
        let mut w = Vector3::zeros();
        let mut about = None;
        if c.keyword(&["V"]).is_some() {
            v = c.vec3("V")?.0;
        }
        if c.keyword(&["W"]).is_some() {
            w = c.vec3("W")?.0;
        }
        if c.keyword(&["ABOUT"]).is_some() {
            about = Some(c.vec3("ABOUT")?.0);
        }
        c.finish()?;
        for id in first..=last {
            let s = if id == first { fs } else { last_span };
            let node = self.node_ref(id, s)?;
            let x = self
                .nodes
                .get(&node)
                .map_or_else(Vector3::zeros, |n| n.position);
            let vel = match about {
                Some(c0) => v + w.cross(&(x - c0)),
                None => v,
            };
            self.initial.push(InitialVelocity {
                node,
                velocity: vel,
                angular: w,
                span,
            });
        }
        Ok(())
    }

    // ---------------------------------------------------------------- ANALYSIS
    pub(super) fn analysis(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "ANALYSIS card");
        c.skip();
        let (kind, _) =
            c.expect_keyword(&["DYNAMIC", "STATIC", "MODES"], "DYNAMIC, STATIC or MODES")?;
        c.ctx = format!("ANALYSIS {kind}");
        if kind == "MODES" {
            // `ANALYSIS MODES n`: the lowest n modes about the initial state; the static
            // analysis of one step is what `mecano-rs modes --static` would solve.
            let (n, s) = c.uint("MODES (number of modes)")?;
            if n < 1 {
                return Err(out_of_range("MODES", "0", ">= 1", s));
            }
            // `ROTATING`: about the relative equilibrium of a hub driven at constant speed;
            // `STATIC [STEPS k]`: about the static equilibrium, reached in k load steps.
            let about = c.keyword(&["ROTATING", "STATIC"]).map(|(k, _)| k);
            let (mut steps, mut proportional) = (1, false);
            if about == Some("STATIC") && c.keyword(&["STEPS"]).is_some() {
                let (k, s) = c.uint("STEPS (number of load steps)")?;
                if k < 1 {
                    return Err(out_of_range("STEPS", "0", ">= 1", s));
                }
                steps = k;
            }
            if about == Some("STATIC") && c.keyword(&["PROPORTIONAL"]).is_some() {
                proportional = true;
            }
            c.finish()?;
            let analysis = Analysis::Static {
                steps,
                newton: NewtonSettings::default(),
                proportional,
            };
            self.set_analysis(analysis, span)?;
            self.modes = Some(n);
            self.modes_rotating = about == Some("ROTATING");
            self.modes_static = about == Some("STATIC");
            self.modes_span = span;
            return Ok(());
        }
        let kws: &[&'static str] = if kind == "DYNAMIC" {
            &[
                "ALPHA", "GENALPHA", "RHOINF", "ESDIRK3", "ESDIRK5", "STEP", "END", "MINSTEP",
                "MAXSTEP", "ADAPTIVE", "TOLPOS", "TOLROT", "GROWTH", "CARRY", "TOL", "TOLINC",
                "MAXIT", "NEWTON",
            ]
        } else {
            &["STEPS", "PROPORTIONAL", "TOL", "TOLINC", "MAXIT", "NEWTON"]
        };
        let mut seen = Seen::default();
        let mut newton = NewtonSettings::default();
        let mut alpha = -0.1;
        // `GENALPHA` (its span, to place a conflict with ALPHA) and `RHOINF ρ`.
        let (mut genalpha, mut rho_inf) = (None, None);
        let (mut step, mut end, mut min, mut max) = (None, None, None, None);
        let (mut tolpos, mut tolrot, mut growth, mut steps) = (None, None, 2.0, 1);
        let mut adaptive = None;
        let mut carry = (Carry::Run, None);
        let mut esdirk = None;
        let mut proportional = false;
        let pos = |v: f64| v > 0.0;
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(kws) else {
                return Err(c.unexpected(t, &expected_list(kws)));
            };
            seen.add(kw, ks, &c.ctx)?;
            match kw {
                "ALPHA" => {
                    alpha = c.number_in("ALPHA (HHT)", "-1/3 <= alpha <= 0", Scheme::alpha_ok)?
                }
                "GENALPHA" => genalpha = Some(ks),
                "RHOINF" => {
                    rho_inf = Some(c.number_in(
                        "RHOINF (generalized-alpha)",
                        "0 <= rho_inf <= 1",
                        Scheme::rho_inf_ok,
                    )?)
                }
                "STEP" => step = Some(c.number("STEP (time step)")?),
                "END" => {
                    let (v, s, t) = c.number("END (end time)")?;
                    if !pos(v) {
                        return Err(out_of_range("END (end time)", t, "> 0 s", s));
                    }
                    end = Some((v, s, t));
                }
                "MINSTEP" => min = Some(c.number("MINSTEP (smallest step)")?),
                "MAXSTEP" => max = Some(c.number("MAXSTEP (largest step)")?),
                "ADAPTIVE" => adaptive = Some(ks),
                "ESDIRK3" | "ESDIRK5" => {
                    let scheme = if kw == "ESDIRK3" {
                        Scheme::Esdirk3
                    } else {
                        Scheme::Esdirk5
                    };
                    if let Some((_, other, _)) = esdirk {
                        return Err(conflict(other, kw, &c.ctx, ks));
                    }
                    esdirk = Some((scheme, kw, ks));
                }
                "TOLPOS" => tolpos = Some(c.number_in("TOLPOS", "> 0 m", pos)?),
                "TOLROT" => tolrot = Some(c.number_in("TOLROT", "> 0 rad", pos)?),
                "GROWTH" => growth = c.number_in("GROWTH", ">= 1", |v| v >= 1.0)?,
                "CARRY" => {
                    let (v, _) = c.expect_keyword(&["RUN", "MODES"], "RUN or MODES")?;
                    let how = if v == "MODES" {
                        Carry::Modes
                    } else {
                        Carry::Run
                    };
                    carry = (how, Some(ks));
                }
                "TOL" => newton.tol_residual = c.number_in("TOL", "> 0", pos)?,
                "TOLINC" => newton.tol_increment = c.number_in("TOLINC", "> 0", pos)?,
                "MAXIT" => {
                    let t = c.peek();
                    let (n, s) = c.uint("MAXIT")?;
                    // A step's Newton loop ends within MAXIT iterations: bounded, so that a
                    // stagnating step cannot hold a run (and its first Ctrl-C) for ever.
                    if !(1..=MAX_NEWTON_ITERATIONS).contains(&n) {
                        let range = format!("1 to {MAX_NEWTON_ITERATIONS}");
                        return Err(out_of_range("MAXIT", t.map_or("", |t| t.text), &range, s));
                    }
                    newton.max_iterations = n;
                }
                "NEWTON" => {
                    let (v, _) = c.expect_keyword(&["FULL", "MODIFIED"], "FULL or MODIFIED")?;
                    newton.modified = v == "MODIFIED";
                }
                "PROPORTIONAL" => proportional = true,
                _ => {
                    let (n, s) = c.uint("STEPS")?;
                    if n < 1 {
                        return Err(out_of_range("STEPS", "0", ">= 1", s));
                    }
                    steps = n;
                }
            }
        }
        let analysis = if kind == "STATIC" {
            Analysis::Static {
                steps,
                newton,
                proportional,
            }
        } else {
            let miss = |what: &str| {
                DeckError::new(
                    K::MissingKeyword {
                        context: c.ctx.clone(),
                        expected: what.into(),
                    },
                    c.end_span(),
                )
            };
            let (h, hs, ht) = step.ok_or_else(|| miss("STEP <time step>"))?;
            if h <= 0.0 {
                return Err(out_of_range("STEP (time step)", ht, "> 0 s", hs));
            }
            let (end, end_span, end_text) = end.ok_or_else(|| miss("END <end time>"))?;
            let min_step = match min {
                None => h / 1024.0,
                Some((v, s, t)) if v <= 0.0 || v > h => {
                    return Err(out_of_range("MINSTEP", t, "0 < MINSTEP <= STEP", s));
                }
                Some((v, _, _)) => v,
            };
            // The run's time t is a sum of steps: it must still resolve a thousandth of
            // the smallest step at the end (the step loop lands on breakpoints and the grid
            // within 1e-3 h), else t + h rounds to t and the run cannot advance.
            if end / min_step > MAX_END_OVER_MINSTEP {
                let found = format!("{end_text} (END/MINSTEP = {:.3e})", end / min_step);
                let range = format!(
                    "END/MINSTEP <= {MAX_END_OVER_MINSTEP:e} (MINSTEP is STEP/1024 by default): \
                     beyond, the time t + h rounds to t in double precision"
                );
                return Err(out_of_range("END (end time)", &found, &range, end_span));
            }
            let max_step = match max {
                None => h,
                Some((v, s, t)) if v < h => {
                    return Err(out_of_range("MAXSTEP", t, "MAXSTEP >= STEP", s));
                }
                Some((v, _, _)) => v,
            };
            let adaptive = match (adaptive, tolpos, tolrot) {
                (Some(_), Some(p), Some(r)) => Some(Adaptive {
                    tol_position: p,
                    tol_rotation: r,
                    max_growth: growth,
                    carry: carry.0,
                }),
                (Some(_), None, _) => return Err(miss("TOLPOS <m> after ADAPTIVE")),
                (Some(_), _, None) => return Err(miss("TOLROT <rad> after ADAPTIVE")),
                (None, _, _) => {
                    for kw in ["TOLPOS", "TOLROT", "GROWTH", "CARRY"] {
                        if seen.has(kw) {
                            return Err(DeckError::new(
                                K::MissingKeyword {
                                    context: format!("{kw} in {}", c.ctx),
                                    expected: "ADAPTIVE".into(),
                                },
                                c.end_span(),
                            ));
                        }
                    }
                    None
                }
            };
            let scheme = match (genalpha, esdirk) {
                (_, Some((_, kw, ks))) if seen.has("ALPHA") => {
                    return Err(conflict("ALPHA", kw, &c.ctx, ks));
                }
                (Some(gs), Some((_, kw, _))) => {
                    return Err(conflict("GENALPHA", kw, &c.ctx, gs));
                }
                (None, Some((scheme, _, _))) if !seen.has("RHOINF") => scheme,
                (Some(gs), None) if seen.has("ALPHA") => {
                    return Err(conflict("ALPHA", "GENALPHA", &c.ctx, gs));
                }
                (Some(_), None) => Scheme::GeneralizedAlpha {
                    rho_inf: rho_inf.unwrap_or(Scheme::DEFAULT_RHO_INF),
                },
                (None, _) if seen.has("RHOINF") => {
                    return Err(DeckError::new(
                        K::MissingKeyword {
                            context: format!("RHOINF in {}", c.ctx),
                            expected: "GENALPHA".into(),
                        },
                        c.end_span(),
                    ));
                }
                (None, _) => Scheme::Hht { alpha },
            };
            // `CARRY MODES` weighs the velocity term of the ESDIRK schemes' estimate; the α
            // family's (Zienkiewicz–Xie's) has none to weigh.
            if let (Carry::Modes, Some(cs)) = carry
                && !matches!(scheme, Scheme::Esdirk3 | Scheme::Esdirk5)
            {
                return Err(DeckError::new(
                    K::MissingKeyword {
                        context: format!("CARRY MODES in {}", c.ctx),
                        expected: "ESDIRK3 or ESDIRK5 (the α schemes' error estimate has no \
                                   velocity term to carry)"
                            .into(),
                    },
                    cs,
                ));
            }
            Analysis::Dynamic {
                scheme,
                step: h,
                end,
                min_step,
                max_step,
                adaptive,
                newton,
            }
        };
        self.set_analysis(analysis, span)
    }

    /// Records the deck's one ANALYSIS card (a second one is an error at its span).
    fn set_analysis(&mut self, analysis: Analysis, span: Span) -> R<()> {
        if let Some((_, first)) = self.analysis {
            let first_line = self.line(first);
            return Err(DeckError::new(
                K::RepeatedCard {
                    keyword: "ANALYSIS".into(),
                    first_line,
                },
                span,
            ));
        }
        self.analysis = Some((analysis, span));
        Ok(())
    }

    // ---------------------------------------------------------------- OUTPUT
    pub(super) fn output(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "OUTPUT card");
        c.skip();
        const KW: [&str; 7] = [
            "NODES", "ELEMENTS", "EVERY", "SUBSTEPS", "DIR", "VTK", "FORMAT",
        ];
        let mut seen = Seen::default();
        let mut out = OutputRequest::default();
        while let Some(t) = c.peek() {
            let Some((kw, ks)) = c.keyword(&KW) else {
                return Err(c.unexpected(t, &expected_list(&KW)));
            };
            seen.add(kw, ks, &c.ctx)?;
            match kw {
                "NODES" | "ELEMENTS" => {
                    let what = if kw == "NODES" { "node" } else { "element" };
                    let sel = if c.keyword(&["ALL"]).is_some() {
                        Selection::All
                    } else if c.keyword(&["NONE"]).is_some() {
                        Selection::None
                    } else {
                        let mut ids = Vec::new();
                        while c.next_is_number() {
                            ids.push(c.uint(&format!("{what} number"))?);
                        }
                        if ids.is_empty() {
                            let e = format!("ALL, NONE or {what} numbers after {kw}");
                            return Err(match c.peek() {
                                Some(t) => c.unexpected(t, &e),
                                None => c.missing(&e),
                            });
                        }
                        Selection::List(ids)
                    };
                    match sel {
                        Selection::List(ids) if kw == "NODES" => {
                            let mut v = Vec::new();
                            for (id, s) in ids {
                                v.push(self.node_ref(id, s)?);
                            }
                            out.nodes = Selection::List(v);
                        }
                        Selection::List(ids) => {
                            let mut v = Vec::new();
                            for (id, s) in ids {
                                if !self.elements.contains_key(&ElementId(id)) {
                                    return Err(DeckError::new(
                                        K::Undefined {
                                            what: "element",
                                            id,
                                        },
                                        s,
                                    ));
                                }
                                v.push(ElementId(id));
                            }
                            out.elements = Selection::List(v);
                        }
                        Selection::All if kw == "NODES" => out.nodes = Selection::All,
                        Selection::All => out.elements = Selection::All,
                        Selection::None if kw == "NODES" => out.nodes = Selection::None,
                        Selection::None => out.elements = Selection::None,
                        Selection::Default => {}
                    }
                }
                "EVERY" => {
                    let (n, s) = c.uint("EVERY (output interval in steps)")?;
                    if n < 1 {
                        return Err(out_of_range("EVERY", "0", ">= 1", s));
                    }
                    out.every = n;
                }
                "SUBSTEPS" => out.substeps = true,
                "DIR" => out.dir = Some(c.next("directory after DIR")?.text.to_string()),
                "FORMAT" => match c.keyword(&["CSV", "NETCDF"]) {
                    Some((f, _)) => out.netcdf = f == "NETCDF",
                    None => {
                        let e = "CSV or NETCDF after FORMAT";
                        return Err(match c.peek() {
                            Some(t) => c.unexpected(t, e),
                            None => c.missing(e),
                        });
                    }
                },
                _ => out.vtk = true,
            }
        }
        if let Some((_, first)) = self.output {
            let first_line = self.line(first);
            return Err(DeckError::new(
                K::RepeatedCard {
                    keyword: "OUTPUT".into(),
                    first_line,
                },
                span,
            ));
        }
        self.output = Some((out, span));
        Ok(())
    }
}
