"""Verification of the FEM core against closed-form solutions (issue 2).

Every expected value here comes from an analytical solution, never from the code itself.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import j0, j1

from twin.fem import AxiMesh, ElasticProblem, Material, ThermalLoads, ThermalProblem

STEEL = Material(k=50.0, rho=7800.0, c=460.0, E=200e9, nu=0.3, alpha=1.2e-5, name="steel")


def on_r(value: float):
    return lambda r, z: np.isclose(r, value)


def on_z(value: float):
    return lambda r, z: np.isclose(z, value)


def shaft_in_sleeve(r_edges, z_edges, r_seat: float, boundaries) -> AxiMesh:
    """A shaft (r < r_seat) in a sleeve, joined across the split interface "seat"."""
    return AxiMesh.structured(
        r_edges,
        z_edges,
        regions={"shaft": lambda r, z: r < r_seat, "sleeve": lambda r, z: r > r_seat},
        boundaries=boundaries,
        interfaces={"seat": on_r(r_seat)},
    )


# --------------------------------------------------------------------------------------
# 1. Manufactured solution with every term: conduction, source, flux, convection, fixed
#    temperature and a contact resistance across an interface.
#    phi = exp(-r) cos z + r², domain r ∈ [0.5, 1.5], z ∈ [0, 1], interface at r = 1.
#    Outer side: T = phi + J(z) with J = R k phi_r(1, z): the flux is continuous (J does
#    not depend on r) and the jump equals R times the flux, as the interface law demands.
# --------------------------------------------------------------------------------------
K_MMS, R_MMS, H_MMS, RC = 2.0, 0.05, 10.0, 1.0


def phi(r, z):
    return np.exp(-r) * np.cos(z) + r**2


def phi_r(r, z):
    return -np.exp(-r) * np.cos(z) + 2 * r


def phi_z(r, z):
    return -np.exp(-r) * np.sin(z)


def jump(z):
    return R_MMS * K_MMS * phi_r(RC, z)


def jump_z(z):
    return R_MMS * K_MMS * np.exp(-RC) * np.sin(z)


def jump_zz(z):
    return R_MMS * K_MMS * np.exp(-RC) * np.cos(z)


def exact_mms(r, z, outer):
    return phi(r, z) + np.where(outer, jump(z), 0.0)


def source_mms(r, z, outer):
    laplace = 4.0 - np.exp(-r) * np.cos(z) / r  # phi_rr + phi_r / r + phi_zz
    return -K_MMS * (laplace + np.where(outer, jump_zz(z), 0.0))


def solve_mms(n: int, order: int) -> float:
    mesh = AxiMesh.structured(
        np.linspace(0.5, 1.5, n + 1),
        np.linspace(0.0, 1.0, n + 1),
        regions={"inner": lambda r, z: r < RC, "outer": lambda r, z: r > RC},
        boundaries={
            "bore": on_r(0.5),
            "surface": on_r(1.5),
            "bottom_inner": lambda r, z: np.isclose(z, 0.0) & (r < RC),
            "bottom_outer": lambda r, z: np.isclose(z, 0.0) & (r > RC),
            "top_inner": lambda r, z: np.isclose(z, 1.0) & (r < RC),
            "top_outer": lambda r, z: np.isclose(z, 1.0) & (r > RC),
        },
        interfaces={"contact": on_r(RC)},
    )
    mat = Material(k=K_MMS, rho=1.0, c=1.0)
    problem = ThermalProblem(mesh, {"inner": mat, "outer": mat}, order=order)
    loads = ThermalLoads(
        sources={
            "inner": lambda r, z: source_mms(r, z, False),
            "outer": lambda r, z: source_mms(r, z, True),
        },
        # flux into the body is k ∇T·n with n the outward normal
        flux={
            "bore": lambda r, z: -K_MMS * phi_r(r, z),
            "top_inner": lambda r, z: K_MMS * phi_z(r, z),
            "top_outer": lambda r, z: K_MMS * (phi_z(r, z) + jump_z(z)),
        },
        convection={
            "surface": (H_MMS, lambda r, z: exact_mms(r, z, True) + K_MMS * phi_r(r, z) / H_MMS)
        },
        fixed_temperature={
            "bottom_inner": lambda r, z: exact_mms(r, z, False),
            "bottom_outer": lambda r, z: exact_mms(r, z, True),
        },
        contact_resistance={"contact": R_MMS},
    )
    T = problem.steady(loads)
    basis = problem.basis
    x = basis.global_coordinates().value
    outer = np.zeros(mesh.n_cells, bool)
    outer[mesh.region("outer")] = True
    err = basis.interpolate(T).value - exact_mms(x[0], x[1], outer[:, None])
    return float(np.sqrt(np.sum(err**2 * x[0] * basis.dx)))


@pytest.mark.parametrize(("order", "rate"), [(1, 2.0), (2, 3.0)])
def test_manufactured_solution_converges_at_the_optimal_rate(order, rate):
    errors = [solve_mms(n, order) for n in (4, 8, 16)]
    rates = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(rates - rate) < 0.25), (errors, rates)
    assert errors[-1] < (1e-3 if order == 1 else 1e-5)


# --------------------------------------------------------------------------------------
# 2. Steady radial conduction: hollow cylinder, flux into the bore, convection outside.
#    T(r) = T∞ + q a/(h b) + (q a / k) ln(b / r)
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("order", [1, 2])
def test_hollow_cylinder_logarithmic_profile(order):
    a, b, q, h, t_inf = 0.02, 0.1, 5e4, 100.0, 20.0
    mesh = AxiMesh.structured(
        np.geomspace(a, b, 41),
        np.linspace(0.0, 0.04, 3),
        boundaries={"bore": on_r(a), "surface": on_r(b)},
    )
    problem = ThermalProblem(mesh, {"body": STEEL}, order=order)
    T = problem.steady(ThermalLoads(flux={"bore": q}, convection={"surface": (h, t_inf)}))
    r = problem.basis.doflocs[0]
    exact = t_inf + q * a / (h * b) + q * a / STEEL.k * np.log(b / r)
    rise = exact.max() - t_inf
    assert np.abs(T - exact).max() < (1e-3 if order == 1 else 1e-5) * rise


# --------------------------------------------------------------------------------------
# 3. Transient cooling of a long solid cylinder in a fluid (Bessel series).
#    θ/θ0 = Σ C_n exp(−λ_n² Fo) J0(λ_n r/a),  λ J1(λ) = Bi J0(λ)
# --------------------------------------------------------------------------------------
def bessel_cooling(r_over_a: np.ndarray, fo: float, bi: float, terms: int = 40) -> np.ndarray:
    roots = []
    for n in range(terms):
        lo, hi = n * np.pi + 1e-9, n * np.pi + np.pi - 1e-9
        # λ_n lies between consecutive zeros of J0 shifted; bracket on [nπ, (n+1)π]
        f = lambda lam: lam * j1(lam) - bi * j0(lam)  # noqa: E731
        grid = np.linspace(lo, hi, 200)
        vals = f(grid)
        idx = np.where(np.sign(vals[:-1]) != np.sign(vals[1:]))[0]
        for i in idx:
            if abs(vals[i]) < 1e3:  # skip poles of the ratio form (none here: no division)
                roots.append(brentq(f, grid[i], grid[i + 1]))
    roots = np.unique(np.round(roots, 12))[:terms]
    out = np.zeros_like(r_over_a)
    for lam in roots:
        c = 2.0 * j1(lam) / (lam * (j0(lam) ** 2 + j1(lam) ** 2))
        out += c * np.exp(-(lam**2) * fo) * j0(lam * r_over_a)
    return out


def test_solid_cylinder_cooling_matches_bessel_series():
    a, h, t0, t_inf = 0.05, 500.0, 100.0, 20.0
    bi = h * a / STEEL.k
    diffusivity = STEEL.k / STEEL.rho_c
    mesh = AxiMesh.structured(
        np.linspace(0.0, a, 41), np.linspace(0.0, 0.01, 3), boundaries={"surface": on_r(a)}
    )
    problem = ThermalProblem(mesh, {"body": STEEL}, order=2)
    loads = ThermalLoads(convection={"surface": (h, t_inf)})
    dt = 0.25
    stepper = problem.transient(loads, dt)
    T_start = np.full(problem.n_dofs, t0)
    r = problem.basis.doflocs[0]
    checked = 0
    for step, T in enumerate(stepper.march(T_start, 400), start=1):
        if step % 100 == 0:
            fo = diffusivity * step * dt / a**2
            exact = t_inf + (t0 - t_inf) * bessel_cooling(r / a, fo, bi)
            assert np.abs(T - exact).max() < 0.005 * (t0 - t_inf), (step, fo)
            checked += 1
    assert checked == 4


def test_crank_nicolson_is_second_order_in_time():
    a, h = 0.05, 500.0
    mesh = AxiMesh.structured(
        np.linspace(0.0, a, 21), np.linspace(0.0, 0.01, 2), boundaries={"surface": on_r(a)}
    )
    problem = ThermalProblem(mesh, {"body": STEEL}, order=2)
    # smooth initial field (the steady profile of a heated core) avoids CN's start-up ringing
    loads = ThermalLoads(convection={"surface": (h, 20.0)})
    r = problem.basis.doflocs[0]
    T0 = 20.0 + 80.0 * np.cos(0.5 * np.pi * r / a) ** 2

    def run(theta, dt, t_end=40.0):
        *_, T = problem.transient(loads, dt, theta=theta).march(T0, round(t_end / dt))
        return T

    reference = run(0.5, 0.0625)
    err_be = [np.abs(run(1.0, dt) - reference).max() for dt in (4.0, 2.0)]
    err_cn = [np.abs(run(0.5, dt) - reference).max() for dt in (4.0, 2.0)]
    assert 1.7 < err_be[0] / err_be[1] < 2.3
    assert 3.4 < err_cn[0] / err_cn[1] < 4.6


# --------------------------------------------------------------------------------------
# 4. Free thermal expansion: u_r = αΔT r, u_z = αΔT z, zero stress — also across a split
#    interface and with two materials of equal α.
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("order", [1, 2])
def test_free_thermal_expansion(order):
    mesh = shaft_in_sleeve(
        np.linspace(0.0, 0.1, 9),
        np.linspace(0.0, 0.2, 9),
        0.05,
        boundaries={"axis": on_r(0.0), "base": on_z(0.0)},
    )
    soft = Material(k=20.0, rho=7000.0, c=500.0, E=70e9, nu=0.33, alpha=STEEL.alpha)
    materials = {"shaft": STEEL, "sleeve": soft}
    elastic = ElasticProblem(mesh, materials, {"axis": "r", "base": "z"}, T_ref=20.0, order=order)
    thermal = ThermalProblem(mesh, materials, order=order)
    dT = 80.0
    T = np.full(thermal.n_dofs, 20.0 + dT)
    u = elastic.solve(T)
    x = elastic.scalar_basis.doflocs
    scale = STEEL.alpha * dT * 0.2
    assert np.abs(u[0] - STEEL.alpha * dT * x[0]).max() < 1e-9 * scale
    assert np.abs(u[1] - STEEL.alpha * dT * x[1]).max() < 1e-9 * scale
    stress_scale = STEEL.E * STEEL.alpha * dT
    for name, s in elastic.stresses(u, T).items():
        assert np.abs(s).max() < 1e-9 * stress_scale, name
    w = elastic.displacement_probe(np.array([0.1, 0.2]), "z")
    assert w @ (T - 20.0) == pytest.approx(STEEL.alpha * dT * 0.2, rel=1e-9)


# --------------------------------------------------------------------------------------
# 5. Long thick-walled cylinder, steady logarithmic temperature T = Ti ln(b/r)/ln(b/a)
#    (Timoshenko & Goodier, thermal stress chapter): radial and hoop stress.
# --------------------------------------------------------------------------------------
def test_thick_cylinder_thermal_stress():
    a, b, ti = 0.05, 0.1, 100.0
    mesh = AxiMesh.structured(
        np.linspace(a, b, 41),
        np.linspace(0.0, 0.01, 3),
        boundaries={"bottom": on_z(0.0), "top": on_z(0.01)},
    )
    # plane strain (ε_z = 0) between the end planes; σ_r and σ_θ equal the free-end values
    elastic = ElasticProblem(mesh, {"body": STEEL}, {"bottom": "z", "top": "z"}, T_ref=0.0, order=2)
    thermal = ThermalProblem(mesh, {"body": STEEL}, order=2)
    r_nodes = thermal.basis.doflocs[0]
    T = ti * np.log(b / r_nodes) / np.log(b / a)
    s = elastic.stresses(elastic.solve(T), T)
    r = elastic.scalar_basis.doflocs[0]
    z = elastic.scalar_basis.doflocs[1]
    c = STEEL.E * STEEL.alpha * ti / (2.0 * (1.0 - STEEL.nu) * np.log(b / a))
    ln = np.log(b / r)
    k = a**2 / (b**2 - a**2) * np.log(b / a)
    sigma_r = c * (-ln - k * (1.0 - b**2 / r**2))
    sigma_t = c * (1.0 - ln - k * (1.0 + b**2 / r**2))
    mid = np.isclose(z, 0.005)
    assert np.abs(s["rr"][mid] - sigma_r[mid]).max() < 0.005 * np.abs(sigma_t).max()
    assert np.abs(s["tt"][mid] - sigma_t[mid]).max() < 0.005 * np.abs(sigma_t).max()
    # plane strain: σ_z = ν(σ_r + σ_θ) − EαT
    sigma_z = STEEL.nu * (sigma_r + sigma_t) - STEEL.E * STEEL.alpha * np.interp(
        r, np.sort(r_nodes), (ti * np.log(b / np.sort(r_nodes)) / np.log(b / a))
    )
    assert np.abs(s["zz"][mid] - sigma_z[mid]).max() < 0.005 * np.abs(sigma_z).max()


# --------------------------------------------------------------------------------------
# 6. Contact resistance between coaxial shells: the jump equals flux × R.
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("order", [1, 2])
def test_contact_resistance_jump_is_flux_times_r(order):
    a, rc, b, q, r_contact = 0.02, 0.05, 0.1, 5e4, 2e-4
    mesh = shaft_in_sleeve(
        np.linspace(a, b, 25),
        np.linspace(0.0, 0.02, 3),
        rc,
        boundaries={"bore": on_r(a), "surface": on_r(b)},
    )
    problem = ThermalProblem(mesh, {"shaft": STEEL, "sleeve": STEEL}, order=order)
    loads = ThermalLoads(
        flux={"bore": q},
        convection={"surface": (200.0, 20.0)},
        contact_resistance={"seat": r_contact},
    )
    T = problem.steady(loads)
    eps = 1e-9
    inside, outside = problem.probe(np.array([[rc - eps, rc + eps], [0.01, 0.01]])) @ T
    flux_at_seat = q * a / rc  # all heat entering the bore crosses the seat
    # exact up to the small z-ripple that the triangles' diagonals give the discrete field
    assert inside - outside == pytest.approx(flux_at_seat * r_contact, rel=1e-4)
    # and the outer shell still follows the log profile from the convective surface
    t_surface = 20.0 + q * a / (200.0 * b)
    expected_out = t_surface + q * a / STEEL.k * np.log(b / rc)
    assert outside == pytest.approx(expected_out, rel=1e-5 if order == 2 else 1e-4)


# --------------------------------------------------------------------------------------
# Conservation: the discrete balance closes to round-off with every kind of load.
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("theta", [1.0, 0.5])
def test_energy_balance_closes_to_round_off(theta):
    mesh = shaft_in_sleeve(
        np.linspace(0.01, 0.08, 15),
        np.linspace(0.0, 0.1, 21),
        0.04,
        boundaries={"bore": on_r(0.01), "surface": on_r(0.08), "end": on_z(0.1)},
    )
    problem = ThermalProblem(mesh, {"shaft": STEEL, "sleeve": STEEL})
    loads = ThermalLoads(
        sources={"shaft": 2e5},
        flux={"bore": 1e3},
        convection={"surface": (300.0, 10.0)},
        fixed_temperature={"end": 15.0},
        contact_resistance={"seat": 5e-4},
    )
    stepper = problem.transient(loads, 4.0, theta=theta)
    T = np.full(problem.n_dofs, 22.0)
    # the same terms straight from the assembled matrices (no reduction to dot products)
    k_data, f = problem.system(loads)
    C, K = problem.ops.csr(problem.capacity_data), problem.ops.csr(k_data)
    films = problem.ops.matrix({"film:surface": 300.0})
    fixed, _ = problem.fixed(loads)
    for T_new in stepper.march(T, 15):
        balance = stepper.energy_balance(T, T_new)
        T_theta = theta * T_new + (1.0 - theta) * T
        scale = balance["heat_in_W"]
        assert abs(balance["residual_W"]) < 1e-9 * scale
        direct = {
            "stored_W": (C @ (T_new - T)).sum() / 4.0,
            "convection_out_W": (films @ T_theta).sum() - 300.0 * 10.0 * problem.facet_load(
                "surface"
            ).sum(),
            "fixed_in_W": (C @ (T_new - T) / 4.0 + K @ T_theta - f)[fixed].sum(),
        }
        for name, value in direct.items():
            assert balance[name] == pytest.approx(value, rel=1e-9, abs=1e-9 * scale), name
        assert problem.energy_balance(T, T_new, loads, 4.0, theta=theta) == balance
        T = T_new
    assert balance["sources_W"] > 0.0 and balance["convection_out_W"] > 0.0
    assert balance["fixed_in_W"] < 0.0  # the 15 °C end draws heat out


# --------------------------------------------------------------------------------------
# Bad input: each a ValueError naming the offending item.
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("field", "value"),
    [("k", 0.0), ("rho", -1.0), ("c", 0.0), ("E", -2e9), ("nu", 0.5), ("nu", -1.0)],
)
def test_bad_material_names_the_field(field, value):
    args = {"k": 1.0, "rho": 1.0, "c": 1.0, "E": 1e9, "nu": 0.3, "alpha": 1e-5}
    args[field] = value
    with pytest.raises(ValueError, match=rf"copper.*{field}"):
        Material(**args, name="copper")


def _box():
    return AxiMesh.structured(
        np.linspace(0.0, 1.0, 3), np.linspace(0.0, 1.0, 3), boundaries={"top": on_z(1.0)}
    )


def test_bad_names_and_steps_are_named():
    mesh = _box()
    with pytest.raises(ValueError, match="'nowhere'"):
        ThermalProblem(mesh, {"nowhere": STEEL})
    problem = ThermalProblem(mesh, {"body": STEEL})
    with pytest.raises(ValueError, match="'sky'"):
        problem.steady(ThermalLoads(convection={"sky": (10.0, 20.0)}))
    with pytest.raises(ValueError, match="'rotor'"):
        problem.steady(ThermalLoads(sources={"rotor": 1.0}, fixed_temperature={"top": 0.0}))
    with pytest.raises(ValueError, match="'gap'"):
        problem.steady(
            ThermalLoads(contact_resistance={"gap": 1e-4}, fixed_temperature={"top": 0.0})
        )
    with pytest.raises(ValueError, match="time step"):
        problem.transient(ThermalLoads(), dt=0.0)
    with pytest.raises(ValueError, match="'top'.*must be ≥ 0"):
        ThermalLoads(convection={"top": (-1.0, 20.0)})
    with pytest.raises(ValueError, match="'seat'.*> 0"):
        ThermalLoads(contact_resistance={"seat": 0.0})
    with pytest.raises(ValueError, match="'bottom'"):
        ElasticProblem(mesh, {"body": STEEL}, {"bottom": "z"})


def test_mesh_without_cells_is_rejected():
    with pytest.raises(ValueError, match="no triangle cells"):
        AxiMesh.from_arrays(np.zeros((2, 3)), np.zeros((3, 0), dtype=int), {})


def test_interface_must_separate_two_regions():
    with pytest.raises(ValueError, match="'seat'.*two regions"):
        AxiMesh.structured(
            np.linspace(0.0, 1.0, 5),
            np.linspace(0.0, 1.0, 5),
            interfaces={"seat": on_r(0.5)},
        )


def test_low_rank_window_update_equals_a_fresh_factorization():
    """A window that changes only contact resistances reuses the factorization (Woodbury);
    its steps must equal those of a direct solve of the same backward-Euler system."""
    import scipy.sparse.linalg as spla

    mesh = shaft_in_sleeve(
        np.linspace(0.01, 0.08, 15),
        np.linspace(0.0, 0.1, 11),
        0.04,
        boundaries={"surface": on_r(0.08)},
    )
    problem = ThermalProblem(mesh, {"shaft": STEEL, "sleeve": STEEL})
    T = np.full(problem.n_dofs, 22.0)
    for r_contact, q in [(1e-4, 1e6), (3e-4, 1.2e6), (5e-5, 0.9e6)]:
        loads = ThermalLoads(
            sources={"shaft": q},
            convection={"surface": (300.0, 22.0)},
            contact_resistance={"seat": r_contact},
        )
        stepper = problem.transient(loads, 4.0)
        k_data, f = problem.system(loads)
        A = problem.ops.csr(problem.capacity_data / 4.0 + k_data).tocsc()
        C = problem.ops.csr(problem.capacity_data / 4.0)
        expected = spla.spsolve(A, C @ T + f)
        T = stepper.step(T)
        assert np.abs(T - expected).max() < 1e-9 * np.abs(expected).max()
    assert len(problem.contact_update) == 1  # one factorization served all windows
