"""One description per benchmark system, from which both engines' inputs are written.

A `System` lists straight fibres of one type (length, segmentation, bending
rigidity κ, hydrodynamic radius), what holds them (clamped points), what
loads them (constant forces on points) and what links them (zero-length
Hookean crosslinks between points), and the medium (viscosity η, kT) and
run (simulated time, frame interval, Cytosim's time steps). Units µm, s, pN.

Fibre drag is Cytosim's (Fiber::dragCoefficientVolume, Tirado & de la
Torre 1979, averaged over orientations):

    ζ = 3πηL / (ln(min(L, cutoff) / 2r) + 0.312),  at least 6πηr,

with r = hydrodynamic_radius (Cytosim's default 0.0125 µm) and the length
cutoff hydrodynamic_radius[1] (default 10 µm), shared equally by the fibre's
n points: γ = ζ/n per point. cellmd is given the same γ per point.
"""

import math
from dataclasses import dataclass, field

K_BOLTZMANN = 1.380649e-5  # pN·µm/K, as cellmd's units::BOLTZMANN_PN_UM_PER_K


@dataclass
class System:
    name: str
    label: str
    length: float  # µm, every fibre
    segmentation: float  # µm, segment length ℓ
    rigidity: float  # κ, pN·µm²
    viscosity: float  # η, Pa·s = pN·s/µm²
    kT: float  # pN·µm
    time: float  # simulated time, s
    frame: float  # interval between frames, s
    dts: tuple  # Cytosim time steps, s
    fibres: list  # [(start (x, y, z), unit direction (dx, dy, dz))]
    clamps: list = field(default_factory=list)  # [(fibre, point)] held in place
    loads: list = field(default_factory=list)  # [(fibre, point, (fx, fy, fz))] constant forces, pN
    links: list = field(default_factory=list)  # [(fibre a, point i, fibre b, point j)] crosslinks
    link_stiffness: float = 0.0  # pN/µm, zero rest length
    radius: float = 0.0125  # Cytosim's hydrodynamic_radius[0], µm
    cutoff: float = 10.0  # Cytosim's hydrodynamic_radius[1], µm
    spring_k: float = 1000.0  # pN/µm, the cellmd springs variants' segment stiffness
    # cellmd's explicit steps, s, for the springs and the constrained variants
    # ("dts": the system's own steps, `dts`; absent: not run, `explicit_note` says why)
    explicit_dt: dict = field(default_factory=dict)
    explicit_note: str = ""
    # `integrator implicit`'s solver for the springs-implicit variant: on the
    # compressed stiff springs of (b), CG stopped converging (step 133)
    implicit_solver: str = "cg"
    clamp_stiffness: float = 1e5  # pN/µm, Cytosim's clamping pickets (cellmd fixes the points)
    load_distance: float = 1e4  # µm, Cytosim's load: a soft picket this far away
    seed: int = 1

    @property
    def segments(self):
        return round(self.length / self.segmentation)

    @property
    def points(self):
        return self.segments + 1

    def drag(self):
        """Cytosim's drag of one fibre ζ (pN·s/µm)."""
        cut = min(self.length, self.cutoff)
        cylinder = 3 * self.length / (math.log(0.5 * cut / self.radius) + 0.312)
        return math.pi * self.viscosity * max(cylinder, 6 * self.radius)

    def point_drag(self):
        return self.drag() / self.points

    def temperature(self):
        """The kelvin temperature cellmd needs for this kT."""
        return self.kT / K_BOLTZMANN

    def steps(self, dt):
        return round(self.time / dt)

    def frame_every(self, dt):
        every = self.frame / dt
        if abs(every - round(every)) > 1e-6 * every or round(every) < 1:
            raise ValueError(f"{self.name}: frame interval {self.frame} s is not a multiple of dt = {dt} s")
        return round(every)

    def point(self, fibre, index):
        (x, y, z), (dx, dy, dz) = self.fibres[fibre]
        s = index * self.segmentation
        return (x + s * dx, y + s * dy, z + s * dz)

    def shrunk(self, fibres, time):
        """The same system with fewer fibres and a shorter run (the smoke mode)."""
        keep = set(range(fibres))
        return System(
            **{
                **self.__dict__,
                "fibres": self.fibres[:fibres],
                "clamps": [c for c in self.clamps if c[0] in keep],
                "loads": [c for c in self.loads if c[0] in keep],
                "links": [c for c in self.links if c[0] in keep and c[2] in keep],
                "time": time,
                "frame": time / 2,
            }
        )


def free_fibres():
    """(a) 50 free thermal actin-like fibres, 5 µm in 0.1 µm segments, 10 s."""
    fibres = [((-2.5, 2.0 * (i % 10), 2.0 * (i // 10)), (1.0, 0.0, 0.0)) for i in range(50)]
    return System(
        name="free",
        label="(a) 50 free thermal fibres",
        length=5.0,
        segmentation=0.1,
        rigidity=0.075,
        viscosity=1.0,
        kT=4.2e-3,
        time=10.0,
        frame=0.5,
        dts=(1e-3, 1e-2),
        fibres=fibres,
        spring_k=1000.0,
        # Explicit limits: stretch γ/(2k) = 8.2e-5 s, bending γℓ³/(8κ) = 2.7e-4 s;
        # inextensible fibres solve their own bending implicitly on the
        # explicit step too, so they run at Cytosim's steps.
        explicit_dt={"springs": 5e-5, "constrained": "dts"},
    )


BUCKLING_LOADS = (0.8, 1.2, 1.5, 2.0, 3.0)  # multiples of the Euler load π²κ/(4L²)

# The microtubule-like fibres of (b) and (c): 5 µm in 20 segments, κ = 20 pN·µm²,
# in a 0.01 Pa·s medium (a cantilever's slowest mode relaxes in ≈ 0.1 s).
MICROTUBULE = dict(length=5.0, segmentation=0.25, rigidity=20.0, viscosity=0.01, kT=4.2e-3, dts=(1e-3, 1e-2), spring_k=1e5)


def buckling():
    """(b) Microtubule-like cantilevers (κ = 20 pN·µm², L = 5 µm, 20 segments)
    clamped at their minus end (first segment held) and pushed at the tip
    along −x by P = 0.8 … 3 × π²κ/(4L²); one fibre per load."""
    euler = math.pi**2 * MICROTUBULE["rigidity"] / (4 * MICROTUBULE["length"] ** 2)
    fibres = [((0.0, 10.0 * i, 0.0), (1.0, 0.0, 0.0)) for i in range(len(BUCKLING_LOADS))]
    tip = round(MICROTUBULE["length"] / MICROTUBULE["segmentation"])
    return System(
        name="buckling",
        label="(b) clamped fibres under compression",
        **MICROTUBULE,
        time=10.0,
        frame=0.25,
        fibres=fibres,
        clamps=[(f, p) for f in range(len(fibres)) for p in (0, 1)],
        loads=[(f, tip, (-m * euler, 0.0, 0.0)) for f, m in enumerate(BUCKLING_LOADS)],
        implicit_solver="cholesky",
        explicit_note="explicit bending limit γℓ³/(8κ) = 3.9e-7 s: 2.6e7 steps",
    )


def bundle():
    """(c) A two-fibre crosslinked bundle: two coincident microtubule-like
    fibres (5 µm, 20 segments) joined by zero-length crosslinks at every
    other point; fibre 1 clamped at its minus end, fibre 2 pulled sideways
    (+y) at its tip by 0.3 pN, so the load reaches the clamp through the links."""
    n = round(MICROTUBULE["length"] / MICROTUBULE["segmentation"])
    fibres = [((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)), ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))]
    return System(
        name="bundle",
        label="(c) crosslinked bundle under a side load",
        **MICROTUBULE,
        time=20.0,
        frame=0.1,
        fibres=fibres,
        clamps=[(0, 0), (0, 1)],
        loads=[(1, n, (0.0, 0.3, 0.0))],
        links=[(0, p, 1, p) for p in range(2, n + 1, 2)],
        link_stiffness=100.0,
        explicit_note="explicit bending limit γℓ³/(8κ) = 3.9e-7 s: 5e7 steps",
    )


SYSTEMS = {"free": free_fibres, "buckling": buckling, "bundle": bundle}
