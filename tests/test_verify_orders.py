"""``ngdual verify`` per order k of PEERS_k: the observed orders of sigma, u and the rotation
against the exact manufactured solutions (elasticity on the unit square, frictionless
contact on Example 3.46's box), with sigma's checked against k + 1."""

import json

import pytest

from ngdual.cli import main
from ngdual.verification import report
from ngdual.verification.order import ORDER_SLACK, order_check

pytestmark = pytest.mark.filterwarnings("ignore::ngdual.solvers.result.PhysicsWarning")


def _orders_run(tmp_path, capsys, orders: list[str]) -> tuple[int, str, dict]:
    path = tmp_path / "verify.json"
    status = main(["verify", "--quick", "--orders", *orders, "--json", str(path)])
    return status, capsys.readouterr().out, json.loads(path.read_text())


def test_verify_orders_0_reports_first_order_stresses_and_the_exact_contact_set(tmp_path,
                                                                                capsys):
    status, out, rows = _orders_run(tmp_path, capsys, ["0"])
    assert status == 0 and "order k of PEERS_k" in out and "pass" in out
    assert not rows["manufactured"] and not rows["benchmarks"]      # the orders alone
    studies = {study["problem"]: study for study in rows["orders"]}
    assert set(studies) == {"elasticity", "contact"}
    for study in studies.values():
        assert study["check"]["passed"] and study["check"]["target"] == 1
        assert all(abs(a - 1) <= ORDER_SLACK for a in study["check"]["observed"])
    last = studies["contact"]["rows"][-1]
    assert last["contact_set"] == 0.0
    assert abs(last["pressure_order"] - 1) <= 0.2, last     # sigma_n^h on Gamma_C (1.09)


@pytest.mark.slow
def test_verify_orders_1_and_2_reach_k_plus_1_and_the_exact_contact_set(tmp_path, capsys):
    """Measured (levels 1-3, sigma): elasticity 1.96, 1.96 (k = 1), 3.09, 3.05 (k = 2);
    contact 2.03, 2.01 (k = 1), 3.06, 2.92 (k = 2)."""
    status, out, rows = _orders_run(tmp_path, capsys, ["1", "2"])
    assert status == 0 and out.count("pass") == 4
    for study in rows["orders"]:
        k = study["order"]
        assert study["check"]["passed"] and study["check"]["target"] == k + 1, study["check"]
        if study["problem"] == "contact":
            assert study["rows"][-1]["contact_set"] == 0.0


def test_an_order_the_family_does_not_have_is_refused_naming_the_flag(capsys):
    assert main(["verify", "--orders", "3"]) == 2
    assert "--orders" in capsys.readouterr().err


def test_an_observed_order_off_its_target_fails_the_check_and_the_command(monkeypatch,
                                                                          capsys):
    rows = [{"order": 1, "level": level, "sigma_order": rate}
            for level, rate in ((1, None), (2, 1.99), (3, 1.70))]
    assert not order_check(rows)["passed"]
    failed = {"problem": "contact", "order": 1, "check": order_check(rows),
              "rows": [{**row, "ndof": 10 * 4 ** row["level"], "seconds": 0.1,
                        "sigma": 1.0, "u": 1.0, "eta": 1.0, "u_order": None,
                        "eta_order": None, "contact_set": 0.0} for row in rows]}
    monkeypatch.setattr(report, "order_rows", lambda orders, plan: [failed])
    assert main(["verify", "--quick", "--orders", "1"]) == 1
    assert "FAIL" in capsys.readouterr().out
