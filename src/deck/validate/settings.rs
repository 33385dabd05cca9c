//! The run settings of a deck: `temperature`, `timestep`, `seed`, `device`,
//! `integrator`, `neighbor`, and the commands that take steps, `minimize`
//! and `run`.

use super::{expect_len, non_negative, options, positive, yes_no, Validator};
use crate::deck::plan::{Action, NeighborSettings};
use crate::gpu::DevicePreference;
use crate::input::{parse_f64, parse_u64, InputError, Token};
use crate::integrate::fire::{FireSettings, MinimizeStyle};
use crate::integrate::implicit::{GpuWorkgroups, ImplicitSettings, LinearSolver};
use crate::integrate::overdamped::OverdampedSettings;
use crate::integrate::Integrator;
use crate::rng::Noise;
use crate::units::UnitSystem;

impl Validator {
    pub(super) fn temperature(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=1, usage)?;
        let what = match self.setup.units {
            UnitSystem::Cell => "a temperature in K",
            UnitSystem::Lj => "a reduced temperature kT",
        };
        let t = non_negative(&s[1], what)?;
        if self.setup.units == UnitSystem::Cell && t > 0.0 && t < 1.0 {
            self.warnings.push(format!(
                "{}:{}:{}: warning: temperature {t} K; did you mean kT? temperature is in kelvin (kT = {:.3e} pN·µm at 300 K)",
                s[1].file.path,
                s[1].line,
                s[1].col,
                self.setup.units.kt(300.0)
            ));
        }
        self.actions.push(Action::Temperature(self.setup.units.kt(t)));
        Ok(())
    }

    pub(super) fn timestep(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=1, usage)?;
        self.actions.push(Action::Timestep(positive(&s[1], "a timestep")?));
        self.timestep_set = true;
        Ok(())
    }

    pub(super) fn seed(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=1, usage)?;
        self.actions.push(Action::Seed(parse_u64(&s[1], "a random seed")?));
        Ok(())
    }

    pub(super) fn device(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=1, usage)?;
        let device = DevicePreference::from_keyword(&s[1].text)
            .ok_or_else(|| s[1].error(format!("found device `{}`, expected `cpu`, `gpu` or `auto`", s[1].text)))?;
        self.actions.push(Action::Device(device));
        Ok(())
    }

    pub(super) fn integrator(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=15, usage)?;
        let implicit = match s[1].text.as_str() {
            "overdamped" => false,
            "implicit" => true,
            other => return Err(s[1].error(format!("found integrator `{other}`, expected `overdamped` or `implicit`"))),
        };
        let keys: &[&str] = if implicit {
            &["noise", "max_displacement", "theta", "solver", "tolerance", "max_iterations", "gpu_workgroups"]
        } else {
            &["noise", "max_displacement", "theta"]
        };
        let opts = options(&s[2..], keys, usage)?;
        let mut settings = OverdampedSettings::default();
        if let Some(t) = opts.get("noise") {
            settings.noise = match t.text.as_str() {
                "uniform" => Noise::Uniform,
                "gaussian" => Noise::Gaussian,
                other => return Err(t.error(format!("found `{other}`, expected `uniform` or `gaussian`"))),
            };
        }
        if let Some(t) = opts.get("max_displacement") {
            settings.max_displacement = positive(t, "a maximum displacement per step")?;
        }
        if let Some(t) = opts.get("theta") {
            let theta = parse_f64(t, "the implicit weight θ")?;
            if !(0.5..=1.0).contains(&theta) {
                return Err(t.error(format!(
                    "found theta {theta}, expected a number in [0.5, 1] (1: backward Euler; 0.5: the trapezoidal rule; below 0.5 stiff modes grow)"
                )));
            }
            settings.theta = theta;
        }
        let mut choice = Integrator::Overdamped(settings);
        if implicit {
            let mut solve = ImplicitSettings::default();
            if let Some(t) = opts.get("solver") {
                solve.solver = match t.text.as_str() {
                    "cg" => LinearSolver::Cg,
                    "cholesky" => LinearSolver::Cholesky,
                    other => return Err(t.error(format!("found solver `{other}`, expected `cg` or `cholesky`"))),
                };
            }
            if let Some(t) = opts.get("tolerance") {
                solve.tolerance = positive(t, "a relative residual tolerance")?;
            }
            if let Some(t) = opts.get("max_iterations") {
                solve.max_iterations = parse_u64(t, "an iteration count")?.max(1) as usize;
            }
            if let Some(t) = opts.get("gpu_workgroups") {
                solve.gpu_workgroups = match t.text.as_str() {
                    "one" => GpuWorkgroups::One,
                    "all" => GpuWorkgroups::All,
                    "auto" => GpuWorkgroups::Auto,
                    other => return Err(t.error(format!("found gpu_workgroups `{other}`, expected `one`, `all` or `auto`"))),
                };
            }
            choice = Integrator::Implicit(settings, solve);
        }
        self.actions.push(Action::Integrator(choice));
        Ok(())
    }

    pub(super) fn neighbor(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 2..=6, usage)?;
        let opts = options(&s[1..], &["skin", "every", "check"], usage)?;
        let mut n = NeighborSettings::default();
        if let Some(t) = opts.get("skin") {
            n.skin = non_negative(t, "a skin distance")?;
        }
        if let Some(t) = opts.get("every") {
            n.every = parse_u64(t, "a step interval")?.max(1);
        }
        if let Some(t) = opts.get("check") {
            n.check = yes_no(t)?;
        }
        self.actions.push(Action::Neighbor(n));
        Ok(())
    }

    pub(super) fn minimize(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        let kw = &s[0];
        let opts = options(&s[1..], &["ftol", "maxiter", "dmax", "style"], usage)?;
        let mut f = FireSettings::default();
        if let Some(t) = opts.get("style") {
            f.style = match t.text.as_str() {
                "fire" => MinimizeStyle::Fire,
                "newton" => MinimizeStyle::Newton,
                other => return Err(t.error(format!("found minimize style `{other}`, expected `fire` or `newton`"))),
            };
        }
        if let Some(t) = opts.get("ftol") {
            f.ftol = positive(t, "a force tolerance")?;
        }
        if let Some(t) = opts.get("maxiter") {
            f.max_iterations = parse_u64(t, "a maximum number of iterations")?;
        }
        if let Some(t) = opts.get("dmax") {
            f.dmax = positive(t, "a maximum move per iteration")?;
        }
        self.model(kw)?;
        if !self.timestep_set {
            return Err(kw.error("`minimize` scales FIRE's step from the timestep; expected a `timestep DT` command before it"));
        }
        self.actions.push(Action::Minimize(f));
        Ok(())
    }

    pub(super) fn run(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        let kw = &s[0];
        expect_len(s, 1..=1, usage)?;
        let n = parse_u64(&s[1], "a number of steps")?;
        self.model(kw)?;
        if !self.timestep_set {
            return Err(kw.error("no timestep; expected a `timestep DT` command before `run`"));
        }
        self.protocols.run();
        self.actions.push(Action::Run(n));
        Ok(())
    }
}
