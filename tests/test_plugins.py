"""A basis or a transfer from outside the package: loaded by ``module:Name`` or an entry point,
checked on numbers before any run, and run on the numpy step when it has no compiled kernels (a
transfer from outside never has)."""

from __future__ import annotations

from importlib.metadata import EntryPoint

import numpy as np
import pytest

from mpm_fem.app.cli import main
from mpm_fem.bases import loader, names, plugins, registry
from mpm_fem.core import transfers
from mpm_fem.core.transfers import plugins as transfer_plugins
from mpm_fem.core.transfers import registry as transfer_registry
from mpm_fem.problems import sod


@pytest.fixture(autouse=True)
def own_registry(monkeypatch):
    """Each test registers into a copy of the registry: no test's basis leaks into another test."""
    monkeypatch.setattr(registry, "_BASES", dict(registry._BASES))
    monkeypatch.setattr(plugins.LOADER, "loaded", {})
    monkeypatch.setattr(plugins.LOADER, "failed", {})
    monkeypatch.setattr(transfer_registry, "_TRANSFERS", dict(transfer_registry._TRANSFERS))
    monkeypatch.setattr(transfer_plugins.LOADER, "loaded", {})
    monkeypatch.setattr(transfer_plugins.LOADER, "failed", {})


def test_a_numpy_only_basis_runs_on_the_numpy_step_and_gives_the_point_mass_numbers():
    assert plugins.resolve("plugin_bases:Hats") == "hats" and "hats" in names()
    assert plugins.resolve("plugin_bases:Hats") == "hats"  # the same spec again: registered once
    settings = dict(h=0.05, ppc=2, T=0.02)
    ours = sod.simulate(sod.SodSettings(basis="hats", **settings), progress=False)
    reference = sod.simulate(sod.SodSettings(basis="mpm", kernel="numpy", **settings), progress=False)
    assert ours.kernel == "numpy" and reference.kernel == "numpy" and ours.steps == reference.steps > 5
    assert np.array_equal(ours.particles.density, reference.particles.density)
    cost = sod.cost(sod.SodSettings(basis="hats", **settings))
    assert cost.kernel == "numpy" and sod.cost(sod.SodSettings(**settings)).kernel == "fused"


def test_a_basis_with_kernels_that_agree_passes_every_check():
    assert plugins.verify(__import__("plugin_bases").HatsCompiled()) is None
    assert plugins.resolve("plugin_bases:HatsCompiled") == "hats_compiled"


@pytest.mark.parametrize("name, check", [
    ("Heavy", "no partition of unity: |sum_i S_ip - 1| up to 0.01"),
    ("NotFinite", "weights S_ip or G_ip are not finite"),
    ("Ragged", "its rows have shapes"),
    ("WrongKernel", "its compiled row differs from its numpy rows"),
    ("Nameless", "lacks the base class Basis"),
    ("NOT_A_CLASS", "lacks the base class Basis"),
    ("Missing", "cannot be loaded"),
])
def test_a_basis_that_breaks_its_contract_is_refused_naming_the_check(name, check, capsys):
    with pytest.raises(plugins.ContractError, match="plugin_bases:" + name):
        plugins.resolve(f"plugin_bases:{name}")
    before = set(names())
    with pytest.raises(SystemExit) as stop:
        main(["sod", "--basis", f"plugin_bases:{name}", "--h", "0.1", "--quiet"])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip()
    assert check in err and "\n" not in err, err
    assert set(names()) == before  # nothing registered


def test_entry_points_register_their_bases_and_a_broken_one_refuses_only_itself(monkeypatch):
    found = [EntryPoint("hats_ep", "plugin_bases:Hats", plugins.ENTRY_POINT_GROUP),
             EntryPoint("heavy_ep", "plugin_bases:Heavy", plugins.ENTRY_POINT_GROUP)]
    monkeypatch.setattr(loader, "entry_points", lambda group: [e for e in found if e.group == group])
    assert plugins.discover() == ("hats",)
    assert "hats" in names() and "heavy" not in names()
    assert plugins.resolve("hats") == "hats"
    with pytest.raises(plugins.ContractError, match="no partition of unity"):
        plugins.resolve("heavy_ep")
    with pytest.raises(ValueError, match="unknown basis 'cubic5'"):
        plugins.resolve("cubic5")


def test_the_command_line_runs_a_spec_and_says_which_kernel_ran(tmp_path, capsys):
    import json

    out = tmp_path / "run"
    assert main(["sod", "--basis", "plugin_bases:Hats", "--h", "0.1", "--ppc", "2", "--T", "0.01", "--out",
                 str(out)]) == 0
    assert "on the numpy step: the basis hats has no compiled kernels" in capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["kernel"] == "numpy" and summary["settings"]["basis"] == "hats"


# ---------------------------------------------------------------- transfers

@pytest.mark.parametrize("flip", [1.0, 0.9])
def test_a_transfer_from_outside_gives_the_flip_numbers_on_the_numpy_step(flip):
    assert transfer_plugins.resolve("plugin_transfers:Flip2") == "flip2" and "flip2" in transfers.names()
    assert transfers.get("flip2").compiled is False  # it claimed kernels: the fused step has none for it
    settings = dict(h=0.05, ppc=2, T=0.02, flip=flip)
    ours = sod.simulate(sod.SodSettings(transfer="flip2", **settings), progress=False)
    reference = sod.simulate(sod.SodSettings(kernel="numpy", **settings), progress=False)
    assert ours.kernel == "numpy" and ours.steps == reference.steps > 5
    for field in ("density", "velocity", "x"):
        gap = np.abs(getattr(ours.particles, field) - getattr(reference.particles, field)).max()
        assert gap <= 1e-12, (field, gap)
    assert np.abs(ours.particles.velocity).max() > 0.1  # the run moved: the comparison compares something
    assert sod.cost(sod.SodSettings(transfer="flip2", **settings)).kernel == "numpy"


def test_the_package_transfers_pass_the_checks_of_one_from_outside():
    assert transfer_plugins.verify(transfers.get("flip")) is None
    assert transfer_plugins.verify(transfers.get("apic")) is None  # affine: C_p carried and conserved too


@pytest.mark.parametrize("name, check", [
    ("Damped", "does not carry a constant velocity: P2G then G2P of v_p = 1.5 is off by 0.01 of it"),
    ("Leaky", "its momentum does not conserve momentum"),
    ("Stretched", "its update returns shapes (41,) and None, not (40,)"),
    ("Exploding", "not finite"),
    ("Nameless", "it has no name"),
    ("Abstract", "cannot be instantiated"),
    ("NotATransfer", "it is not a Transfer (mpm_fem.core.transfers.Transfer), got NotATransfer"),
    ("Missing", "cannot be loaded"),
])
def test_a_transfer_that_breaks_its_contract_is_refused_naming_the_check(name, check, capsys):
    with pytest.raises(transfer_plugins.ContractError, match="plugin_transfers:" + name):
        transfer_plugins.resolve(f"plugin_transfers:{name}")
    before = set(transfers.names())
    with pytest.raises(SystemExit) as stop:
        main(["burgers", "--transfer", f"plugin_transfers:{name}", "--h", "0.1", "--quiet"])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "argument --transfer" in err and check in err and "\n" not in err, err
    assert set(transfers.names()) == before  # nothing registered


def test_transfer_entry_points_register_and_a_broken_one_refuses_only_itself(monkeypatch):
    group = transfer_plugins.ENTRY_POINT_GROUP
    found = [EntryPoint("flip2_ep", "plugin_transfers:Flip2", group),
             EntryPoint("damped_ep", "plugin_transfers:Damped", group),
             EntryPoint("hats_ep", "plugin_bases:Hats", plugins.ENTRY_POINT_GROUP)]
    monkeypatch.setattr(loader, "entry_points", lambda group: [e for e in found if e.group == group])
    assert transfer_plugins.discover() == ("flip2",)
    assert "flip2" in transfers.names() and "damped" not in transfers.names() and "hats" not in names()
    with pytest.raises(transfer_plugins.ContractError, match="does not carry a constant velocity"):
        transfer_plugins.resolve("damped_ep")
    with pytest.raises(ValueError, match="unknown transfer 'pic2'"):
        transfer_plugins.resolve("pic2")


def test_the_command_line_runs_a_transfer_spec_on_the_numpy_step_and_says_so(tmp_path, capsys):
    import json

    out = tmp_path / "run"
    assert main(["burgers", "--transfer", "plugin_transfers:Flip2", "--h", "0.1", "--T", "0.01", "--out",
                 str(out)]) == 0
    assert "on the numpy step: the transfer flip2 has no compiled kernels" in capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["kernel"] == "numpy" and summary["settings"]["transfer"] == "flip2"
