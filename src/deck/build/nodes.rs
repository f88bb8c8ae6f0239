//! Stage 2, NODES and FIX: positions, generations, fixities.

use super::cursor::*;
use super::*;

impl Builder<'_> {
    // ---------------------------------------------------------------- NODES
    pub(super) fn fix_dofs(c: &mut Cursor<'_, '_>, fixed: &mut Fixity) -> R<()> {
        const DOFS: [&str; 9] = ["ALL", "TRANS", "ROT", "X", "Y", "Z", "RX", "RY", "RZ"];
        let mut any = false;
        while let Some(t) = c.peek() {
            let Some((kw, _)) = c.keyword(&DOFS) else {
                return Err(c.unexpected(t, &expected_list(&DOFS)));
            };
            any = true;
            let range = match kw {
                "ALL" => 0..6,
                "TRANS" => 0..3,
                "ROT" => 3..6,
                "X" => 0..1,
                "Y" => 1..2,
                "Z" => 2..3,
                "RX" => 3..4,
                "RY" => 4..5,
                _ => 5..6,
            };
            for f in &mut fixed[range] {
                *f = true;
            }
        }
        if any {
            Ok(())
        } else {
            Err(c.missing("degrees of freedom after FIX (ALL, TRANS, ROT, X, Y, Z, RX, RY, RZ)"))
        }
    }

    pub(super) fn add_node(
        &mut self,
        id: u32,
        position: Vector3<f64>,
        fixed: Fixity,
        span: Span,
        at: Span,
    ) {
        if let Some(first) = self.nodes.get(&NodeId(id)).map(|n| n.span) {
            self.duplicate("node", id, first, at);
            return;
        }
        self.nodes.insert(
            NodeId(id),
            Node {
                id: NodeId(id),
                position,
                fixed,
                span,
            },
        );
        self.free_dofs += fixed.iter().filter(|f| !**f).count() as u64;
    }

    pub(super) fn node(&mut self, card: &Card<'_>) -> R<()> {
        let span = card.span();
        let mut c = Cursor::new(card, "NODES card");
        let (id, id_span) = c.uint("node number")?;
        c.ctx = format!("node {id}");
        if c.keyword(&["TO"]).is_some() {
            let (last, last_span) = c.uint("last node number of the generation")?;
            c.ctx = format!("nodes {id} TO {last}");
            c.expect_keyword(&["LINE"], "LINE")?;
            let (p1, _, _) = c.vec3("first point")?;
            let (p2, _, _) = c.vec3("last point")?;
            let mut fixed = [false; 6];
            if c.keyword(&["FIX"]).is_some() {
                Self::fix_dofs(&mut c, &mut fixed)?;
            }
            c.finish()?;
            if last <= id {
                return Err(DeckError::new(
                    K::BadGeneration {
                        first: id,
                        last,
                        reason: "the last number must be greater than the first".into(),
                    },
                    Span::new(id_span.start, last_span.end),
                ));
            }
            let at = Span::new(id_span.start, last_span.end);
            generation_size(id, last, at)?;
            self.fits(u64::from(last - id) + 1, 0, id, last, at)?;
            let n = last - id;
            for i in 0..=n {
                let p = if i == 0 {
                    p1
                } else if i == n {
                    p2
                } else {
                    p1 + (p2 - p1) * (f64::from(i) / f64::from(n))
                };
                self.add_node(id + i, p, fixed, span, id_span);
            }
            return Ok(());
        }
        let (p, _, _) = c.vec3("coordinates")?;
        let mut fixed = [false; 6];
        if c.keyword(&["FIX"]).is_some() {
            Self::fix_dofs(&mut c, &mut fixed)?;
        }
        c.finish()?;
        self.add_node(id, p, fixed, span, id_span);
        Ok(())
    }

    pub(super) fn fix_card(&mut self, card: &Card<'_>) -> R<()> {
        let mut c = Cursor::new(card, "FIX card");
        c.skip();
        let (id, id_span) = c.uint("node number")?;
        let node = self.node_ref(id, id_span)?;
        let mut fixed = [false; 6];
        Self::fix_dofs(&mut c, &mut fixed)?;
        if let Some(n) = self.nodes.get_mut(&node) {
            for (f, add) in n.fixed.iter_mut().zip(fixed) {
                *f |= add;
            }
        }
        Ok(())
    }
}
