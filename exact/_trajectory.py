"""Result objects of :func:`exact.simulate`."""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from typing import TYPE_CHECKING, overload

import numpy as np

from peelapprox import BRANCHES, PeelParams
from peelapprox.io import fmt_number, html_table, optional_import, param_attrs
from peelapprox.validate import finite, integer, nonnegative, optional, positive

from ._registry import model_of

if TYPE_CHECKING:
    from peelapprox import ForceSeries

__all__ = ["Trajectory", "Jumps", "Jump", "State", "SolverStats"]

#: Units of the columns of :meth:`Trajectory.to_dataframe` and :meth:`Jumps.to_dataframe` (``df.attrs["units"]``).
_UNITS = {"t": "s", "alpha": "rad", "omega": "rad/s", "F": "N", "v": "m/s", "Vp": "m/s", "branch": "",
          "from_branch": "", "to_branch": "", "v_before": "m/s", "v_after": "m/s"}


def _variant_units(params) -> dict[str, str]:
    """The fields of PeelParams that the model of ``params`` reads beyond the paper's, with their units
    (``Model.parameters``: the repr, the DataFrame's attrs): ``{}`` for the paper's model."""
    return dict(model_of(params).parameters)


def _variant_fields(params) -> dict:
    """The fields of :func:`_variant_units` that are set in ``params`` (tape mass, load): ``{}`` for the paper's
    model."""
    return {n: getattr(params, n) for n in _variant_units(params) if getattr(params, n) is not None}


def _branches(pd, codes: np.ndarray):
    """Branch codes (0, 1) as a pandas categorical of the names ``"AB"``/``"CD"`` (:data:`BRANCHES`)."""
    return pd.Categorical.from_codes(np.asarray(codes, dtype=np.int8), categories=list(BRANCHES))


@dataclass(frozen=True)
class State:
    """A point of the orbit: time, ``(α, ω, F, v)``, the branch name and, under a load, the pull speed ``Vp``."""

    t: float
    alpha: float
    omega: float
    F: float
    v: float
    branch: str
    Vp: float | None = None  # the pull speed [m/s] under a load (loading="load"); None under velocity control

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        if d["Vp"] is None:  # velocity control: the dict as before the field existed
            del d["Vp"]
        return d


@dataclass(frozen=True)
class Jump:
    """One stick-slip jump at a fold: (α, ω, F) continuous, v jumps."""

    t: float
    from_branch: str
    to_branch: str
    alpha: float
    omega: float
    F: float
    v_before: float
    v_after: float


@dataclass(frozen=True)
class Jumps:
    """All stored jumps, as arrays (memory proportional to the number of jumps).

    ``from_branch``/``to_branch`` hold integer codes into :data:`BRANCHES`
    (0 = AB, 1 = CD).  Index it to get a :class:`Jump`.
    """

    t: np.ndarray
    from_branch: np.ndarray
    to_branch: np.ndarray
    alpha: np.ndarray
    omega: np.ndarray
    F: np.ndarray
    v_before: np.ndarray
    v_after: np.ndarray

    FIELDS = ("t", "from_branch", "to_branch", "alpha", "omega", "F", "v_before", "v_after")

    @classmethod
    def from_buffer(cls, buf: np.ndarray) -> Jumps:
        buf = np.asarray(buf, dtype=float).reshape(-1, 8)
        return cls(
            t=buf[:, 0].copy(),
            from_branch=buf[:, 1].astype(np.int8),
            to_branch=buf[:, 2].astype(np.int8),
            alpha=buf[:, 3].copy(),
            omega=buf[:, 4].copy(),
            F=buf[:, 5].copy(),
            v_before=buf[:, 6].copy(),
            v_after=buf[:, 7].copy(),
        )

    def __len__(self) -> int:
        return len(self.t)

    @overload
    def __getitem__(self, i: int | np.integer) -> Jump: ...

    @overload
    def __getitem__(self, i: slice | np.ndarray | list) -> Jumps: ...

    def __getitem__(self, i):
        """``jumps[k]``: one :class:`Jump`; ``jumps[2:5]``, ``jumps[mask]`` (a boolean array of ``len(jumps)``)
        or ``jumps[[0, 3]]``: the selected jumps as :class:`Jumps` (numpy's indexing of every field)."""
        if isinstance(i, (slice, list, np.ndarray)):
            idx = np.asarray(i) if not isinstance(i, slice) else i
            if isinstance(idx, np.ndarray) and idx.dtype == bool and idx.shape != self.t.shape:
                raise IndexError(f"a boolean mask of Jumps must have {len(self)} entries, got shape {idx.shape}")
            return Jumps(**{f: getattr(self, f)[idx] for f in self.FIELDS})
        if isinstance(i, (bool, np.bool_)) or not isinstance(i, (int, np.integer)):
            raise TypeError(f"Jumps indices are integers, slices, boolean masks or integer lists, got "
                            f"{type(i).__name__}")
        return Jump(
            float(self.t[i]),
            BRANCHES[int(self.from_branch[i])],
            BRANCHES[int(self.to_branch[i])],
            float(self.alpha[i]),
            float(self.omega[i]),
            float(self.F[i]),
            float(self.v_before[i]),
            float(self.v_after[i]),
        )

    def __iter__(self):
        return (self[i] for i in range(len(self)))

    def to_csv(self, path, extra: dict | None = None) -> None:
        """Write one row per jump with a header (branch names spelled out), floats in full precision (``repr``);
        ``extra``: constant columns appended to every row (e.g. the law that produced the run), quoted as CSV
        needs."""
        import csv

        extra = dict(extra or {})
        with open(path, "w", newline="") as fh:
            w = csv.writer(fh, lineterminator="\n")
            w.writerow([*self.FIELDS, *extra])
            for j in self:
                w.writerow([repr(j.t), j.from_branch, j.to_branch, repr(j.alpha), repr(j.omega), repr(j.F),
                            repr(j.v_before), repr(j.v_after), *extra.values()])

    def to_dataframe(self):
        """The jumps as a :class:`pandas.DataFrame`, one row per jump: columns :attr:`FIELDS`, the branches as a
        categorical of the names ``"AB"``/``"CD"``, the floats the arrays themselves; ``df.attrs["units"]``.

        Raises
        ------
        ImportError
            If pandas is not installed (``pip install 'peelapprox[data]'``).
        """
        pd = optional_import("pandas", "Jumps.to_dataframe")
        cols = {f: getattr(self, f) for f in self.FIELDS}
        cols["from_branch"], cols["to_branch"] = _branches(pd, self.from_branch), _branches(pd, self.to_branch)
        df = pd.DataFrame(cols)
        df.attrs["units"] = {f: _UNITS[f] for f in self.FIELDS}
        return df

    def _summary(self) -> dict:
        n = len(self)
        out: dict = {"jumps": n, "AB→CD": int(np.count_nonzero(self.from_branch == 0)),
                     "CD→AB": int(np.count_nonzero(self.from_branch == 1))}
        if n:
            out.update({"t [s]": f"{fmt_number(self.t[0], 6)} … {fmt_number(self.t[-1], 6)}",
                        "F [N]": f"{fmt_number(self.F.min(), 6)} … {fmt_number(self.F.max(), 6)}"})
        return out

    def __repr__(self) -> str:
        d = self._summary()
        rng = f", t {d['t [s]']} s, F {d['F [N]']} N" if len(self) else ""
        return f"Jumps({d['jumps']} jumps: {d['AB→CD']} AB→CD, {d['CD→AB']} CD→AB{rng})"

    def _repr_html_(self) -> str:
        return html_table("Jumps", self._summary())


@dataclass(frozen=True)
class SolverStats:
    """Work counters of one run.

    ``n_steps`` accepted steps, ``n_rejected`` rejected step attempts (None where
    the solver does not report it: scipy's solvers),
    ``n_rhs`` right-hand-side evaluations (all stages, dense-output stages and
    starting-step probes), ``n_jac`` Jacobian evaluations and ``n_lu`` LU
    factorisations (regularised method only), ``n_jumps`` all jumps (also
    those before ``t_transient``), ``wall_time`` [s] of the integration
    excluding one-off compilation, ``compile_time`` [s] spent compiling or
    loading the kernels in this call (0 when already loaded).
    """

    n_steps: int
    n_rejected: int | None
    n_rhs: int
    n_jumps: int
    wall_time: float
    compile_time: float = 0.0
    n_jac: int = 0
    n_lu: int = 0


class Trajectory:
    """An orbit of the peeling model as computed by :func:`exact.simulate`.

    Attributes
    ----------
    t, alpha, omega, F, v : ndarray
        Stored points.  ``t`` is non-decreasing; equal consecutive times occur
        only at a jump, where the two rows hold the states just before (``v``
        at the fold) and just after (``v`` at the landing root).
    branch : ndarray of int8
        0 (AB) or 1 (CD) at each stored point; names in :data:`BRANCHES`.
    jumps : Jumps
        Every jump with ``t >= t_transient``.
    stats : SolverStats
    params : PeelParams
    method, solver : str
    rtol : float
    atol : ndarray
    eps : float or None
        Regularisation parameter (``method="regularized"`` only).
    Vp : ndarray or None
        The pull speed [m/s] at the stored points under a load (a model with the state ``Vp``); None under
        velocity control (the pull speed is ``params.V``).
    initial_state, final_state : State
        Where the run started and ended (``final_state`` continues a run).
    status : int
        0 = reached ``t_end``.  Failed runs raise instead of returning.
    message : str
    """

    def __init__(
        self,
        *,
        t,
        alpha,
        omega,
        F,
        v,
        branch,
        jumps: Jumps,
        stats: SolverStats,
        params: PeelParams,
        method: str,
        solver: str,
        rtol: float,
        atol,
        eps: float | None,
        initial_state: State,
        final_state: State,
        t_end: float,
        t_transient: float,
        status: int = 0,
        message: str = "reached t_end",
        Vp=None,
    ):
        self.t = np.asarray(t, dtype=float)
        self.alpha = np.asarray(alpha, dtype=float)
        self.omega = np.asarray(omega, dtype=float)
        self.F = np.asarray(F, dtype=float)
        self.v = np.asarray(v, dtype=float)
        self.branch = np.asarray(branch, dtype=np.int8)
        self.jumps = jumps
        self.stats = stats
        self.params = params
        self.method = method
        self.solver = solver
        self.rtol = float(rtol)
        self.atol = np.asarray(atol, dtype=float)
        self.eps = eps
        self.initial_state = initial_state
        self.final_state = final_state
        self.t_end = float(t_end)
        self.t_transient = float(t_transient)
        self.status = status
        self.message = message
        self.Vp = None if Vp is None else np.asarray(Vp, dtype=float)

    def __repr__(self) -> str:
        p = self.params
        units = _variant_units(p)
        var = "".join(f", {n}={v!r}" + (f" {units[n]}" if units[n] else "")
                      for n, v in _variant_fields(p).items())  # the model variant, if any
        return (
            f"Trajectory(V={p.V}, I={p.I}{var}, method={self.method!r}, t=[{self.initial_state.t}, {self.t_end}], "
            f"points={len(self.t)}, jumps={len(self.jumps)}, steps={self.stats.n_steps}, "
            f"wall_time={self.stats.wall_time:.3g}s)"
        )

    @property
    def branch_names(self) -> np.ndarray:
        """Branch of each stored point as strings ``"AB"``/``"CD"``."""
        return np.asarray(BRANCHES)[self.branch]

    @property
    def closure_c(self) -> np.ndarray:
        """``c(α) = -cos θ`` at the stored points (the model's closure)."""
        return np.asarray(self.params.closure(self.alpha)[0], dtype=float)

    def constraint_residual(self, relative: bool = False) -> np.ndarray:
        """``F (1 - cos θ) - f(v, V)`` at every stored point (CONSTR) [N].

        With ``relative=True``, divided by ``f(v, V)``.  f is the run's law ``params.force``.
        """
        if len(self.t) == 0:
            return np.zeros(0)
        f = np.asarray(self.params.force.f(self.v, self.params.V))  # the paper's: peel_force itself (bitwise)
        r = self.F * (1.0 + self.closure_c) - f
        return r / f if relative else r

    # ------------------------------------------------------------ I/O
    def to_npz(self, path) -> None:
        """Save everything (arrays, jumps, counters, settings) to a ``.npz``."""
        meta = {
            "params": dataclasses.asdict(self.params),
            "stats": dataclasses.asdict(self.stats),
            "method": self.method,
            "solver": self.solver,
            "rtol": self.rtol,
            "eps": self.eps,
            "initial_state": self.initial_state.as_dict(),
            "final_state": self.final_state.as_dict(),
            "t_end": self.t_end,
            "t_transient": self.t_transient,
            "status": self.status,
            "message": self.message,
        }
        jb = np.column_stack([np.asarray(getattr(self.jumps, f), dtype=float) for f in Jumps.FIELDS]) if len(
            self.jumps
        ) else np.zeros((0, 8))
        np.savez_compressed(
            path,
            t=self.t,
            alpha=self.alpha,
            omega=self.omega,
            F=self.F,
            v=self.v,
            branch=self.branch,
            jumps=jb,
            atol=self.atol,
            meta=np.array(json.dumps(meta)),
            **({} if self.Vp is None else {"Vp": self.Vp}),  # type: ignore[arg-type]
        )

    @classmethod
    def from_npz(cls, path) -> Trajectory:
        """Load a trajectory written by :meth:`to_npz`, every field checked against its schema
        (``exact/_trajectory_file.py``): a ValueError naming the file and the field otherwise."""
        from ._trajectory_file import read_trajectory

        return read_trajectory(cls, path, {"State": State, "SolverStats": SolverStats, "Jumps": Jumps})

    def _repr_html_(self) -> str:
        p, st = self.params, self.stats
        units = _variant_units(p)
        return html_table("Trajectory", {
            "V [m/s]": p.V, "I [kg m²]": p.I, "k [N/m]": p.k, "force": repr(p.force),
            **{f"{n} [{units[n]}]" if units[n] else n: v for n, v in _variant_fields(p).items()},
            "method": self.method,
            "t [s]": f"{fmt_number(self.initial_state.t, 6)} … {fmt_number(self.t_end, 6)}",
            "points": len(self.t), "jumps": len(self.jumps), "steps": st.n_steps,
            "wall time [s]": st.wall_time, "final state": (f"α={fmt_number(self.final_state.alpha, 6)} rad, "
                                                           f"F={fmt_number(self.final_state.F, 6)} N, "
                                                           f"branch {self.final_state.branch}")})

    def as_series(self, rate: float, *, noise: float = 0.0, drift: float = 0.0, seed: int | None = None,
                  t_start: float | None = None) -> ForceSeries:
        """The pull force as a tensile machine would record it: a :class:`peelapprox.ForceSeries` sampled at
        ``rate`` [Hz] from ``t_start`` (default: the first stored time at or after ``t_transient``) to ``t_end``.

        Where the stored times are the sampling grid (a run with ``t_eval=np.arange(t0, t_end, 1/rate)``) the
        samples are the solver's own values; otherwise F is interpolated linearly between the stored points,
        and ``source`` says so with the largest gap between them (F is smooth between jumps and continuous at
        them; a gap longer than ``1/rate`` loses detail: run with ``t_eval`` on the grid instead).

        Parameters
        ----------
        rate : float
            Sampling rate [Hz], in (0, 1e9].
        noise : float
            Standard deviation [N] of Gaussian white noise added to every sample (0).
        drift : float
            A linear drift of the force [N] over the series, from 0 at its start to ``drift`` at its end (0).
        seed : int, optional
            Of the noise's generator (:func:`numpy.random.default_rng`); None: fresh entropy.
        t_start : float, optional
            First sample time [s].

        Returns
        -------
        ForceSeries
            With ``V`` the run's pull speed and ``source`` saying how it was sampled.
        """
        rate = positive("rate", rate)
        if rate > 1e9:
            raise ValueError(f"rate must be at most 1e9 Hz, got {rate!r}")
        noise = nonnegative("noise", noise)
        drift = finite("drift", drift)
        seed = optional(integer, "seed", seed, lo=0, hi=2**63 - 1)
        keep = self.t >= (self.t_transient if t_start is None else float(t_start))
        t, F = self.t[keep], self.F[keep]
        if t.size < 2:
            raise ValueError("the trajectory stores fewer than 2 points after t_start: nothing to sample")
        grid = t[0] + np.arange(int(np.floor((t[-1] - t[0]) * rate + 1e-9)) + 1) / rate
        if grid.size == t.size and np.allclose(grid, t, rtol=0.0, atol=1e-9 / rate):
            Fs, how = F.copy(), "the solver's values on the grid"
        else:
            uniq = np.concatenate(([True], np.diff(t) > 0))  # a jump's two rows share F: keep one
            Fs = np.interp(grid, t[uniq], F[uniq])
            how = (f"interpolated linearly between {int(uniq.sum())} stored points (largest gap "
                   f"{fmt_number(float(np.max(np.diff(t[uniq]))), 3)} s)")
        if drift:
            Fs = Fs + drift * (grid - grid[0]) / max(float(grid[-1] - grid[0]), 1e-300)
        if noise:
            Fs = Fs + np.random.default_rng(seed).normal(0.0, noise, grid.size)
        p = self.params
        source = (f"exact.simulate(V = {fmt_number(p.V, 6)} m/s, I = {fmt_number(p.I, 4)} kg m^2) sampled at "
                  f"{fmt_number(rate, 6)} Hz ({how}), noise {fmt_number(noise, 3)} N, drift {fmt_number(drift, 3)} N")
        from peelapprox import ForceSeries  # on first use: a first simulate needs no force-trace analysis

        return ForceSeries(grid, Fs, V=float(p.V), source=source)

    def to_dataframe(self):
        """The stored points as a :class:`pandas.DataFrame`: columns ``t, alpha, omega, F, v`` (the arrays
        themselves, float64), under a load (a model with the state ``Vp``) also ``Vp`` (the pull speed [m/s]), and
        ``branch`` (a categorical of the names ``"AB"``/``"CD"``), one row per stored point (a jump is two rows
        at the same ``t``).

        ``df.attrs`` holds ``units`` (per column), ``params`` (:func:`peelapprox.io.param_attrs`: V, I, k, R,
        l, geometry and the law ``force``, with its ``force_key``; for a model variant also the fields set of
        ``tape_mass`` [kg], ``loading``, ``load_mass`` [kg], ``load`` [N], their units in ``variant_units``) and
        the run's ``method``, ``solver``, ``rtol``, ``eps``, ``t_transient``, ``t_end``.  The jumps:
        ``self.jumps.to_dataframe()``.

        Raises
        ------
        ImportError
            If pandas is not installed (``pip install 'peelapprox[data]'``).
        """
        pd = optional_import("pandas", "Trajectory.to_dataframe")
        cols = ["t", "alpha", "omega", "F", "v"] + ([] if self.Vp is None else ["Vp"])
        df = pd.DataFrame({**{c: getattr(self, c) for c in cols}, "branch": _branches(pd, self.branch)})
        var = _variant_fields(self.params)
        df.attrs.update({"units": {c: _UNITS[c] for c in (*cols, "branch")},
                         "params": {**param_attrs(self.params), **var},
                         "method": self.method, "solver": self.solver, "rtol": self.rtol, "eps": self.eps,
                         "t_transient": self.t_transient, "t_end": self.t_end})
        if var:
            units = _variant_units(self.params)
            df.attrs["variant_units"] = {n: units[n] for n in var}
        return df
