//! Helpers for integration tests: write a deck with its topology and force field
//! into a temporary directory, validate it and run it.

#![allow(dead_code)]

use std::path::{Path, PathBuf};

use cellmd::deck::{validate_file, Plan};
use cellmd::run::{RunOptions, Simulation};

pub struct Case {
    pub dir: tempfile::TempDir,
}

impl Case {
    /// Files as (name, contents); the deck is `deck.in`.
    pub fn new(files: &[(&str, &str)]) -> Self {
        let dir = tempfile::tempdir().unwrap();
        for (name, text) in files {
            std::fs::write(dir.path().join(name), text).unwrap();
        }
        Self { dir }
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    pub fn plan(&self) -> Plan {
        validate_file(&self.path("deck.in"), &[]).unwrap_or_else(|e| panic!("{e}"))
    }

    pub fn run(&self) -> Simulation {
        let plan = self.plan();
        Simulation::execute(&plan, RunOptions { output_dir: self.dir.path().to_path_buf(), ..Default::default() })
            .unwrap_or_else(|e| panic!("{e}"))
    }

    pub fn output_dir(&self) -> &Path {
        self.dir.path()
    }
}

/// A topology of `n` free particles of type `p` on a cubic grid of spacing `a`.
pub fn grid_topology(n_side: usize, a: f64) -> String {
    let mut top = String::from("[ particles ]\n");
    let mut id = 1;
    for i in 0..n_side {
        for j in 0..n_side {
            for k in 0..n_side {
                top += &format!("{id} p {} {} {}\n", i as f64 * a, j as f64 * a, k as f64 * a);
                id += 1;
            }
        }
    }
    top
}
