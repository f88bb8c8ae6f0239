//! The cases a plan means: the grid (factorial or zipped), the random samples, their
//! combination, and each case's overrides and directory.

use super::draws::open_unit;
use super::*;

impl Plan {
    /// The grid points (factorial or zipped) of the non-random parameters: for each, the
    /// values of the grid parameters in plan order.
    pub(super) fn grid(&self) -> Result<Vec<Vec<f64>>, String> {
        let lists: Vec<&Vec<f64>> = self
            .params
            .iter()
            .filter_map(|p| match &p.variation {
                Variation::Grid { values, .. } => Some(values),
                _ => None,
            })
            .collect();
        if lists.is_empty() {
            return Ok(vec![vec![]]);
        }
        if self.zip {
            let n = lists[0].len();
            if lists.iter().any(|l| l.len() != n) {
                let lens: Vec<String> = lists.iter().map(|l| l.len().to_string()).collect();
                return Err(format!(
                    "combine = \"zip\" needs lists of one length, found {}",
                    lens.join(", ")
                ));
            }
            return Ok((0..n)
                .map(|i| lists.iter().map(|l| l[i]).collect())
                .collect());
        }
        let total = lists
            .iter()
            .try_fold(1usize, |acc, l| {
                acc.checked_mul(l.len()).filter(|&t| t <= MAX_CASES)
            })
            .ok_or(format!(
                "the factorial product has more than {MAX_CASES} cases"
            ))?;
        let mut out = Vec::with_capacity(total);
        for mut i in 0..total {
            let mut row = vec![0.0; lists.len()];
            for (k, l) in lists.iter().enumerate().rev() {
                row[k] = l[i % l.len()];
                i /= l.len();
            }
            out.push(row);
        }
        Ok(out)
    }

    /// The random samples: for each, the values of the random parameters in plan order.
    pub(super) fn random(&self) -> Vec<Vec<f64>> {
        let dists: Vec<&Variation> = self
            .params
            .iter()
            .map(|p| &p.variation)
            .filter(|v| v.is_random())
            .collect();
        if dists.is_empty() {
            return vec![vec![]];
        }
        let n = self.samples;
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        let mut out = vec![vec![0.0; dists.len()]; n];
        match self.sampling {
            Sampling::MonteCarlo => {
                for row in out.iter_mut() {
                    for (j, d) in dists.iter().enumerate() {
                        row[j] = d.at(open_unit(&mut rng));
                    }
                }
            }
            Sampling::LatinHypercube => {
                for (j, d) in dists.iter().enumerate() {
                    let mut perm: Vec<usize> = (0..n).collect();
                    for i in (1..n).rev() {
                        let k = (rng.next_u64() % (i as u64 + 1)) as usize;
                        perm.swap(i, k);
                    }
                    for (i, row) in out.iter_mut().enumerate() {
                        let u = (perm[i] as f64 + open_unit(&mut rng)) / n as f64;
                        row[j] = d.at(u);
                    }
                }
            }
        }
        out
    }

    pub(super) fn generate(&self) -> Result<Vec<Vec<f64>>, String> {
        let grid = self.grid()?;
        if grid.len().saturating_mul(self.samples) > MAX_CASES {
            return Err(format!("more than {MAX_CASES} cases"));
        }
        let random = self.random();
        let mut cases = Vec::with_capacity(grid.len() * random.len());
        for g in &grid {
            for r in &random {
                let (mut gi, mut ri) = (g.iter(), r.iter());
                let row: Vec<f64> = self
                    .params
                    .iter()
                    .map(|p| {
                        let v = if p.variation.is_random() {
                            ri.next()
                        } else {
                            gi.next()
                        };
                        v.copied().unwrap_or(f64::NAN)
                    })
                    .collect();
                cases.push(row);
            }
        }
        Ok(cases)
    }

    /// Case `i`'s overrides: (parameter name, value).
    pub fn overrides(&self, i: usize) -> Vec<(String, f64)> {
        self.params
            .iter()
            .zip(&self.cases[i])
            .map(|(p, v)| (p.name.clone(), *v))
            .collect()
    }

    /// The directory of case `i`: `<out>/cases/<i, zero-padded>`.
    pub fn case_dir(&self, i: usize) -> PathBuf {
        let width = self.cases.len().saturating_sub(1).to_string().len().max(4);
        self.out.join("cases").join(format!("{i:0width$}"))
    }

    /// Whether exactly one parameter varies, on a grid (a 1-D sweep: curves of the
    /// quantities against it).
    pub fn one_dimensional(&self) -> Option<usize> {
        let grid: Vec<usize> = (0..self.params.len())
            .filter(|&k| matches!(&self.params[k].variation, Variation::Grid { values, .. } if values.len() > 1))
            .collect();
        (grid.len() == 1 && !self.params.iter().any(|p| p.variation.is_random())).then(|| grid[0])
    }
}
