//! Neighbour search: a cell list feeding a Verlet list with a skin (CPU).
//!
//! # What is built
//!
//! [`NeighborList::build`] finds every pair `(i, j)`, `i ≠ j`, not excluded
//! by [`Exclusions`], with
//!
//! ```text
//! |d_ij|² < r_list²,   d_ij = minimum_image(x_j − x_i),   r_list = cutoff + skin
//! ```
//!
//! and stores it in CSR form, particle `i`'s neighbours being
//! `neighbors[offsets[i]..offsets[i+1]]`, **sorted ascending by `j`**:
//!
//! - a **full** list ([`NeighborList::new`]): `j` appears in `i`'s list and
//!   `i` in `j`'s, so each particle can gather its own terms (the contact
//!   search and bond formation use it);
//! - a **half** list ([`NeighborList::half`]): only `j > i`, each pair once,
//!   for Newton's-third-law force passes (the CPU pair forces: half the
//!   memory and half the distance tests).
//!
//! Sorting makes the order of every per-particle force sum a function of the
//! pair set alone, not of the cell layout or of when the list happened to be
//! rebuilt, which is what bit-reproducible runs need.
//!
//! # Skin and rebuild criterion
//!
//! The list stays valid while no particle has moved more than `skin/2` since
//! the last build: two particles then approach by at most `skin`, so every
//! pair now within `cutoff` was within `cutoff + skin` at build time.
//! [`NeighborList::needs_rebuild`] measures each displacement with the
//! minimum image, `|minimum_image(x_i − x_i^build)| > skin/2`, so wrapping
//! across a periodic face is not mistaken for a jump of a box length (this
//! assumes a particle moves less than half a box between two checks). A
//! change of the box or of the particle count also requires a rebuild.
//!
//! # Cell list
//!
//! Each axis of length `L` is cut into `n = ⌊L / w_min⌋` cells (at least one)
//! of edge `w = L/n ≥ w_min`, where
//! `w_min = r_list·(1 + 10⁻⁹) + 8·ε·max|coordinate|` adds a rounding margin so
//! that two particles closer than `r_list` can never land two cells apart.
//! Every partner of a particle is then in its own cell or an adjacent one
//! (27 cells at most).
//!
//! * **Periodic axes**: the coordinate is wrapped into `[lo, hi)` first and
//!   neighbouring cells wrap around. With fewer than three cells on an axis the
//!   offsets −1, 0, +1 would name the same cell twice; they are deduplicated.
//!   A periodic edge shorter than `2·r_list` is an error for a plain list
//!   (the minimum image of a pair within range would be ambiguous); a list
//!   made [`NeighborList::with_periodic_images`] (the pair forces') instead
//!   lists every pair with some image in range and walks their images
//!   ([`ImageShifts`], module `images`), as LAMMPS' ghost atoms do.
//! * **Non-periodic axes**: particles outside `[lo, hi)` are put in the
//!   nearest edge cell. The clamped cell index is still monotone and
//!   1-Lipschitz in the coordinate, so partners remain in adjacent cells.
//! * **Grid cap**: a huge box with a tiny cutoff would ask for an absurd
//!   number of cells; the total is capped at `max(8·N, 27)` by merging cells
//!   (which only makes them larger, so the search stays exact).
//! * `cutoff + skin = 0` (no pair interaction) or `N = 0` gives empty lists
//!   and no grid.
//!
//! Particles are binned by a stable counting sort and each particle's list is
//! gathered independently in parallel (rayon), then sorted, so the result is
//! identical for any thread count.
//!
//! * **Excluded type pairs** ([`Exclusions::with_type_pairs`]): each cell is
//!   binned by particle type too, and a particle visits only the bins of the
//!   types it may pair with, so pairs of types no rule acts between cost
//!   nothing (not even a distance test). The cells are then capped at
//!   `max(8·N/types, 27)`, so the bins stay about as many as the cells
//!   without types.
//!
//! # Example
//!
//! ```
//! use cellmd::neighbor::{Exclusions, NeighborList};
//! use cellmd::system::SimBox;
//! use glam::DVec3;
//!
//! let sim_box = SimBox::new(DVec3::ZERO, DVec3::splat(10.0), [true, true, true]);
//! let x = vec![DVec3::new(0.1, 5.0, 5.0), DVec3::new(9.8, 5.0, 5.0), DVec3::new(5.0, 5.0, 5.0)];
//! let mut list = NeighborList::new(1.0, 0.2);
//! list.build(&x, &sim_box, &Exclusions::none()).unwrap();
//! assert_eq!(list.neighbors(0), &[1]); // across the periodic face
//! assert!(list.neighbors(2).is_empty());
//! assert!(!list.needs_rebuild(&x, &sim_box));
//! ```

mod exclusions;
mod images;
mod verlet;

pub use self::exclusions::Exclusions;
pub use self::images::{ImageShifts, MAX_IMAGES_PER_PAIR};
pub use self::verlet::NeighborList;
