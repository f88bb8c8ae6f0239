//! Cost of the sweep machinery around the runs (`cargo bench --bench sweep`):
//!
//! * `case_overhead`: one case of `sweeps/bounce.toml` through `runner::run_case` (parse
//!   the deck with the case's values, run, write, compute the quantities, write
//!   `case.json`) against the bare run (`app::run_model` on a parsed model) of the same
//!   case: the difference is the sweep's per-case overhead, to set against a 1-second case
//!   (target: below 5 %, i.e. 50 ms);
//! * `collect_10000`: assembling `sweep.csv`, `statistics.csv` and the figures of a
//!   10,000-case random plan from 10,000 case directories (synthetic `case.json` files,
//!   written once) — the target is a few seconds of CPU.
//!
//! The parallel speed-up of a 20-case sweep of 1-second cases (`--jobs 2` against
//! `--jobs 1`) takes minutes per sample: `benches/sweep_speedup.sh` measures it.

use criterion::{Criterion, criterion_group, criterion_main};
use mecano::sweep::plan::Plan;
use mecano::sweep::runner::{self, CaseRecord, Status};
use std::path::{Path, PathBuf};
use std::time::Duration;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("mecano_bench_sweep_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch dir");
    d
}

fn case_overhead(c: &mut Criterion) {
    let out = scratch("case");
    let plan = Plan::load(&root().join("sweeps/bounce.toml"), Some(&out)).expect("plan");
    let model = mecano::deck::load_deck_with(&plan.deck, &plan.overrides(4)).expect("deck");
    let mut g = c.benchmark_group("sweep");
    g.measurement_time(Duration::from_secs(5));
    g.bench_function("bare_run", |b| {
        let dir = out.join("bare");
        b.iter(|| mecano::app::run_model(&model, "bounce", &dir, true).expect("run"))
    });
    g.bench_function("case_overhead_run_case", |b| {
        b.iter(|| {
            let _ = std::fs::remove_dir_all(plan.case_dir(4));
            runner::run_case(&plan, 4, &mecano::interrupt::Interrupts::none()).expect("case")
        })
    });
    g.finish();
    let _ = std::fs::remove_dir_all(&out);
}

fn write_cases(plan: &Plan) {
    for i in 0..plan.cases.len() {
        let dir = plan.case_dir(i);
        std::fs::create_dir_all(&dir).expect("case dir");
        let rec = CaseRecord {
            case: i,
            values: plan.cases[i].clone(),
            status: Status::Ok,
            diagnosis: String::new(),
            steps: 10_000,
            time: 1.0,
            cpu_s: 1.0,
            quantities: vec![Some(plan.cases[i][0] * 1e-13), Some(0.5)],
            quantity_names: vec!["z".into(), "t".into()],
            deck_hash: plan.deck_hash.clone(),
        };
        std::fs::write(
            dir.join("case.json"),
            serde_json::to_string_pretty(&rec).expect("json"),
        )
        .expect("write");
    }
}

fn collect_10000(c: &mut Criterion) {
    let out = scratch("collect");
    let text = "deck = \"../decks/pendulum_sweep.dat\"\nsamples = 10000\nseed = 1\n\
        [[parameter]]\nname = \"E\"\ndistribution = \"lognormal\"\nmedian = 2.1e11\nsigma = 0.05\n\
        [[quantity]]\nname = \"z\"\nnode = 12\ncolumn = \"z\"\nstat = \"max_abs\"\n\
        [[quantity]]\nname = \"t\"\nelement = 23\ncolumn = \"active\"\nstat = \"first_time_above\"\n";
    let plan = Plan::parse(text, &root().join("sweeps/big.toml"), Some(&out)).expect("plan");
    write_cases(&plan);
    let mut g = c.benchmark_group("sweep");
    g.sample_size(10);
    g.bench_function("collect_10000", |b| {
        b.iter(|| mecano::sweep::collect_and_draw(&plan).expect("collect"))
    });
    g.finish();
    let _ = std::fs::remove_dir_all(Path::new(&out));
}

criterion_group!(benches, case_overhead, collect_10000);
criterion_main!(benches);
