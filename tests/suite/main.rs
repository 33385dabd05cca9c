//! cellmd's integration tests as one binary, a module per subject (the GPU
//! ones are `gpu` and `gpu_*`); `common` holds the helpers they share.
//!
//! One binary, not one per file: rebuilt after a change to the library
//! (2 cores, `cargo build --timings`), the 46 binaries took 190 s, each
//! compiling the helpers and the generic code it instantiates again and
//! linking alone; this one takes 50 s. One pool of test threads also packs
//! the long tests with the short ones.
//! `cargo test --test suite gpu_implicit::` runs one module.

mod common;

mod adhesion;
mod architecture;
mod backend_bruteforce;
mod bad_decks;
mod blowup;
mod bond_rest;
mod build;
mod cell_compression;
mod collagen;
mod compose;
mod constraints;
mod contact;
mod contractile_lattice;
mod crash_safety;
mod crashers;
mod custom;
mod cytosim_bench;
mod deck_features;
mod deck_language;
mod docs;
mod docs_snippets;
mod doublet;
mod dynamics;
mod export_lammps;
mod filaments;
mod force_dipole;
mod formats;
mod golden;
mod gpu;
mod gpu_bind;
mod gpu_constraints;
mod gpu_implicit;
mod gpu_kinetics;
mod gpu_minimize;
mod hertz;
mod implicit;
mod import_lammps;
mod inextensible_fibres;
mod inputs;
mod kinetics;
mod lammps_mutations;
mod measure;
mod mutations;
mod nodal_pressure;
mod protocols;
mod readme;
mod reproducibility;
mod shear;
mod shells;
mod spheroid_spreading;
mod survive;
mod tensegrity_substrate;
mod tissue_fracture;
