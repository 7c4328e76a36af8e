"""twin.fem.stepper's general θ-method (theta_step, picard, march_to) on systems whose exact
solution is known (a lumped body cooling or heating, C dT/dt + K T = f), and against the
factorized ThermalStepper of the same system."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from twin.fem import AxiMesh, Material, ThermalLoads, ThermalProblem, stepper
from twin.fem.stepper import StepControl, SteppingError, ThetaSystem, theta_step

C_J_K, K_W_K, T_INF_C = 400.0, 2.0, 20.0  # one lumped body: time constant C/K = 200 s


def body(load_W: float = K_W_K * T_INF_C) -> ThetaSystem:
    return ThetaSystem(sp.csr_matrix([[K_W_K]]), sp.csr_matrix([[C_J_K]]), np.array([load_W]))


def solve(A: sp.csr_matrix, rhs: np.ndarray) -> np.ndarray:
    return rhs / A.toarray().ravel()


@pytest.mark.parametrize("theta", [0.5, 2 / 3, 1.0])
def test_theta_step_is_the_theta_recurrence(theta):
    """One step of C dT/dt + K T = f with f changing over the step:
    T1 = ((C/Δt − (1−θ)K) T0 + θ f1 + (1−θ) f0) / (C/Δt + θK)."""
    dt, T0, f0, f1 = 10.0, 80.0, 40.0, 100.0
    T1 = theta_step(np.array([T0]), dt, theta, body(f0), lambda T: body(f1), solve, False)
    exact = ((C_J_K / dt - (1 - theta) * K_W_K) * T0 + theta * f1 + (1 - theta) * f0) / (
        C_J_K / dt + theta * K_W_K)
    assert T1[0] == pytest.approx(exact, rel=1e-14)


def test_picard_finds_the_fixed_point_and_refuses_a_divergent_one():
    # k(T) = 1 + T/100 W/K, f = 3 W: k(T) T = f is T²/100 + T − 3 = 0
    root = (-1.0 + math.sqrt(1.0 + 4 * 3.0 / 100.0)) / (2 / 100.0)
    T = stepper.picard(lambda T: 3.0 / (1.0 + T / 100.0), np.array([0.0]))
    assert T[0] == pytest.approx(root, rel=1e-7)
    with pytest.raises(SteppingError, match="Picard"):
        stepper.picard(lambda T: -2.0 * T + 1.0, np.array([0.0]))  # |slope| > 1: no convergence


@pytest.mark.parametrize("theta, order", [(1.0, 1), (0.5, 2)])
def test_march_to_fixed_steps_converge_at_the_method_order(theta, order):
    """Cooling from 80 °C towards 20 °C: T(t) = 20 + 60 e^(−t/200); the error at t = 100 s
    falls by 2^order when Δt halves; the last step lands on t1 exactly."""

    def step(T, t, t_next, h):
        return theta_step(T, h, theta, body(), lambda T1: body(), solve, False)

    exact = T_INF_C + 60.0 * math.exp(-100.0 / (C_J_K / K_W_K))
    errors = []
    for dt in (30.0, 15.0):  # 30 does not divide 100: the last step is shortened
        times, temps = stepper.march_to(step, np.array([80.0]), 0.0, 100.0, dt)
        assert times[-1] == 100.0
        errors.append(abs(temps[-1][0] - exact))
    assert 2**order * 0.8 < errors[0] / errors[1] < 2**order * 1.25


def cooling(T, t, t_next, h):
    """One backward-Euler step of the lumped body cooling toward T_INF_C."""
    return theta_step(T, h, 1.0, body(), lambda T1: body(), solve, False)


def test_march_to_adaptive_meets_its_tolerance():
    """Step doubling keeps the local error of each step near the tolerance (× the range the
    temperatures span, at most 60 °C here), so the end value is within (number of steps) ×
    that of the exact exponential."""
    control = StepControl(dt_min=0.01, dt_max=50.0, tolerance=1e-3 / 60.0)
    times, temps = stepper.march_to(cooling, np.array([80.0]), 0.0, 400.0, 1.0, control)
    exact = T_INF_C + 60.0 * math.exp(-2.0)
    assert times[-1] == 400.0 and np.all(np.diff(times) > 0)
    assert abs(temps[-1][0] - exact) < 1e-3 * len(times)
    assert max(np.diff([0.0, *times])) > 1.0  # the step grew where the error allowed


def test_march_to_adaptive_takes_the_first_substep_given_and_grows_at_most_threefold():
    """MAPDL's AUTOTS: DELTIM's DTIME is the starting substep, taken even when its error
    estimate exceeds the tolerance (a linear step converges, so nothing bisects it); the
    next size is predicted smaller from that error, and later ones grow at most
    OPNCONTROL's thermal OPENUPFACTOR (3) a step.  The end value still meets the
    exponential to the tolerance per step plus the first step's own error."""
    control = StepControl(dt_min=1e-3, dt_max=100.0, tolerance=1e-3 / 60.0)
    times, temps = stepper.march_to(cooling, np.array([80.0]), 0.0, 400.0, 40.0, control)
    sizes = np.diff([0.0, *times])
    assert sizes[0] == 40.0 and sizes[1] < 0.5 * sizes[0]
    assert np.all(sizes[1:-1] <= stepper.OPEN_UP_FACTOR * sizes[:-2] * (1 + 1e-12))
    assert sizes[-2] > 2.0 * sizes[1]  # grew again as the error allowed
    # one backward-Euler step of 40 s (two of 20 s kept) from 80 °C: its error, decayed
    first = T_INF_C + 60.0 / (1 + 20.0 / 200.0) ** 2
    first_error = (first - (T_INF_C + 60.0 * math.exp(-40.0 / 200.0))) * math.exp(-360 / 200)
    exact = T_INF_C + 60.0 * math.exp(-2.0)
    assert temps[-1][0] - exact > first_error  # the first step was not redone smaller
    assert temps[-1][0] - exact - first_error < 1e-3 * len(times)


def _doubling_error(step, T, t, h):
    full = step(T, t, t + h, h)
    half = step(step(T, t, t + h / 2, h / 2), t + h / 2, t + h, h / 2)
    return float(np.max(np.abs(full - half)))


def test_march_to_bisects_a_substep_whose_error_is_too_large():
    """AUTOTS's bisection: a substep whose error estimate is more than BISECTION_RATIO × the
    tolerance is redone at half the size, so no kept substep after the first one (and
    above DTMIN) exceeds it, even where the load jumps (the film's bulk temperature from
    20 to 220 °C at t = 100 s, which the prediction from the smooth start cannot foresee).
    The tolerance is relative to the range the temperatures have reached."""

    def heated(T, t, t_next, h):
        def system(time):
            return body(K_W_K * (220.0 if time > 100.0 else T_INF_C))
        return theta_step(T, h, 1.0, system(t), lambda T1: system(t_next), solve, False)

    tolerance = 1e-4
    control = StepControl(dt_min=1e-3, dt_max=100.0, tolerance=tolerance)
    times, temps = stepper.march_to(heated, np.array([20.5]), 0.0, 400.0, 1.0, control)
    starts = [0.0, *times[:-1]]
    states = [np.array([20.5]), *temps[:-1]]
    values = np.array([20.5, *(float(T[0]) for T in temps)])
    for i in range(1, len(times)):
        h = times[i] - starts[i]
        kept = values[: i + 1]  # the start and the substeps kept before this one
        limit = stepper.BISECTION_RATIO * tolerance * max(1.0, float(np.ptp(kept)))
        assert _doubling_error(heated, states[i], starts[i], h) <= limit * (1 + 1e-9), i
    exact = 220.0 - 200.0 * math.exp(-300.0 / 200.0)  # from ~20.5 °C at t = 100 s
    assert temps[-1][0] == pytest.approx(exact, abs=0.5)


def test_march_to_lands_on_the_end_in_equal_substeps():
    """The substeps land on the load step's end: a rest shorter than two predicted substeps
    is split in two equal ones rather than a full one and a sliver, unless a half would be
    below DTMIN; a response that does not change lets each size grow threefold."""
    control = StepControl(dt_min=0.1, dt_max=4.0, tolerance=1e-3)
    times, _ = stepper.march_to(lambda T, t, t_next, h: T, np.array([1.0]), 0.0, 10.0, 1.0,
                                control)
    assert np.diff([0.0, *times]) == pytest.approx([1.0, 3.0, 3.0, 3.0], rel=1e-12)
    assert times[-1] == 10.0
    control = StepControl(dt_min=0.5, dt_max=0.5, tolerance=1e-3)
    times, _ = stepper.march_to(lambda T, t, t_next, h: T, np.array([1.0]), 0.0, 1.7, 0.5,
                                control)
    assert np.diff([0.0, *times]) == pytest.approx([0.5, 0.5, 0.5, 0.2], rel=1e-9)


def test_march_to_bisects_a_step_that_fails_and_gives_up_at_dt_min():
    """Bisection answers a step that does not converge: the step is redone at half the
    size until it passes, and the error goes out once the size is DTMIN."""

    def step(T, t, t_next, h):
        if h > 0.3:
            raise SteppingError("did not converge")
        return T + h

    control = StepControl(dt_min=0.1, dt_max=1.0, tolerance=1.0)
    times, temps = stepper.march_to(step, np.array([0.0]), 0.0, 1.0, 1.0, control)
    assert times[0] == pytest.approx(0.25) and times[-1] == 1.0
    assert temps[-1][0] == pytest.approx(1.0)
    with pytest.raises(SteppingError, match="converge"):
        stepper.march_to(step, np.array([0.0]), 0.0, 1.0, 1.0,
                         StepControl(dt_min=0.5, dt_max=1.0, tolerance=1.0))


def test_march_to_refuses_too_many_substeps():
    n = stepper.MAX_SUBSTEPS
    with pytest.raises(SteppingError, match=f"more than {n} substeps"):
        stepper.march_to(lambda T, t, t_next, h: T, np.array([1.0]), 0.0, 1.0, 1.0 / (n + 10))


@pytest.mark.parametrize("theta", [0.5, 1.0])
def test_thermal_stepper_is_theta_step_with_fixed_operators(theta):
    """ThermalProblem.transient's factorized stepper and theta_step on the problem's own K,
    C and f are the same θ-method: equal to round-off over ten steps (a heated disk cooled
    by a film, no prescribed temperature)."""
    mesh = AxiMesh.structured(np.linspace(0.0, 0.05, 11), np.linspace(0.0, 0.02, 5),
                              boundaries={"rim": lambda r, z: np.isclose(r, 0.05)})
    problem = ThermalProblem(mesh, {"body": Material(k=50.0, rho=7800.0, c=460.0)})
    loads = ThermalLoads(sources={"body": 2e6}, convection={"rim": (500.0, 20.0)})
    k_data, f = problem.system(loads)
    system = ThetaSystem(problem.ops.csr(k_data), problem.ops.csr(problem.capacity_data), f)
    dt, T0 = 5.0, np.full(problem.n_dofs, 20.0)
    fixed = list(problem.transient(loads, dt, theta=theta).march(T0, 10))
    T = T0
    for T_fixed in fixed:
        T = theta_step(T, dt, theta, system, lambda T1: system,
                       lambda A, rhs: spla.spsolve(A.tocsc(), rhs), False)
        assert np.abs(T - T_fixed).max() < 1e-9 * np.abs(T_fixed - 20.0).max()
    assert fixed[-1].max() > 21.0  # the disk did heat up


def test_capacity_rate_kept_per_time_step_gives_a_fresh_problems_bits():
    """ThermalProblem keeps C/Δt per Δt (backward Euler's explicit side, asked for every
    step of a loop that re-evaluates its loads): steps of Δt = 2, 4, 2 s and Crank–Nicolson
    after them are those of a problem that never stepped before, to the bit, and the kept
    matrix cannot be changed through a stepper."""
    def make() -> ThermalProblem:  # a shaft in a sleeve: the contact's low-rank solver
        mesh = AxiMesh.structured(
            np.linspace(0.0, 0.05, 11), np.linspace(0.0, 0.02, 5),
            regions={"shaft": lambda r, z: r < 0.025, "sleeve": lambda r, z: r > 0.025},
            boundaries={"rim": lambda r, z: np.isclose(r, 0.05)},
            interfaces={"fit": lambda r, z: np.isclose(r, 0.025)})
        steel = Material(k=50.0, rho=7800.0, c=460.0)
        return ThermalProblem(mesh, {"shaft": steel, "sleeve": steel})

    loads = ThermalLoads(sources={"shaft": 2e6}, convection={"rim": (500.0, 20.0)},
                         contact_resistance={"fit": 2e-4})
    problem = make()
    T = np.full(problem.n_dofs, 20.0)
    for dt, theta in ((2.0, 1.0), (4.0, 1.0), (2.0, 1.0), (2.0, 0.5)):
        stepper = problem.transient(loads, dt, theta=theta)
        fresh = make().transient(loads, dt, theta=theta)
        np.testing.assert_array_equal(stepper.step(T), fresh.step(T))
        np.testing.assert_array_equal(stepper.explicit.toarray(), fresh.explicit.toarray())
        T = stepper.step(T)
    assert sorted(problem._capacity_rates) == [2.0, 4.0]
    with pytest.raises(ValueError, match="read-only"):
        problem.transient(loads, 2.0).explicit.data[0] = 0.0


def test_a_problem_on_mesh_views_keeps_each_views_sets_apart():
    """ThermalProblem.on_mesh: two owners name a set "hot" and "cold" on views of one
    mesh (other cells and faces each) and step through copies of one problem that has
    stepped before: each solves to the bits of a problem assembled on a mesh holding its
    sets, and the shared mesh and problem hold neither set; a mesh that is no view of the
    problem's is refused."""
    def make_mesh() -> AxiMesh:
        return AxiMesh.structured(
            np.linspace(0.0, 0.05, 11), np.linspace(0.0, 0.02, 5),
            regions={"shaft": lambda r, z: r < 0.025, "sleeve": lambda r, z: r > 0.025},
            boundaries={"rim": lambda r, z: np.isclose(r, 0.05)},
            interfaces={"fit": lambda r, z: np.isclose(r, 0.025)})

    steel = {"shaft": Material(k=50.0, rho=7800.0, c=460.0),
             "sleeve": Material(k=40.0, rho=7800.0, c=460.0)}
    mesh = make_mesh()
    problem = ThermalProblem(mesh, steel)
    loads = ThermalLoads(sources={"shaft": 2e6}, convection={"rim": (500.0, 20.0)},
                         contact_resistance={"fit": 2e-4})
    T = problem.transient(loads, 2.0).step(np.full(problem.n_dofs, 20.0))
    centroid_z = mesh.thermal.p[1, mesh.thermal.t].mean(axis=0)
    outer = mesh.thermal.boundary_facets()
    bottom = outer[np.isclose(mesh.thermal.p[1, mesh.thermal.facets[:, outer]].mean(axis=0), 0)]
    sets = [(np.nonzero(centroid_z < 0.01)[0], bottom[:4]),
            (np.nonzero(centroid_z > 0.01)[0], bottom[4:])]
    terms, sources = set(problem.ops._terms), set(problem._source_vectors)
    hot = ThermalLoads(sources={"shaft": 2e6, "hot": 1e6},
                       convection={"rim": (500.0, 20.0), "cold": (80.0, 15.0)},
                       contact_resistance={"fit": 2e-4})
    for cells, facets in sets:
        view = mesh.view()
        view.add_region("hot", cells)
        view.add_boundary("cold", facets)
        copy = problem.on_mesh(view)
        assert copy.conduction_data is problem.conduction_data  # nothing assembled anew
        own = make_mesh()
        own.add_region("hot", cells)
        own.add_boundary("cold", facets)
        for dt in (2.0, 4.0):
            np.testing.assert_array_equal(copy.transient(hot, dt).step(T),
                                          ThermalProblem(own, steel).transient(hot, dt).step(T))
    assert set(mesh.regions) == {"shaft", "sleeve"} and set(mesh.boundaries) == {"rim"}
    assert set(problem.ops._terms) == terms and set(problem._source_vectors) == sources
    with pytest.raises(ValueError, match="not a view"):
        problem.on_mesh(make_mesh())
    replaced = mesh.view()
    replaced.add_region("shaft", sets[0][0])
    with pytest.raises(ValueError, match="not a view"):
        problem.on_mesh(replaced)
