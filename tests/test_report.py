"""The report lists every claim of STUDY.md, measured or not."""

from mpm_fem.report import CLAIMS, claims_index, write_report
from mpm_fem.study import StudyOptions


class _FakeStudy:
    @staticmethod
    def report(folder):
        return "## fake\n\nA section.\n"

    @staticmethod
    def claims(folder):
        return [{"id": "C5", "verdict": "confirmed", "evidence": "order 1.02"},
                {"id": "E1 (sod)", "verdict": "partly", "evidence": "does not add up"}]


def test_every_claim_appears_in_the_index_with_a_verdict():
    lines = claims_index({"fake": _FakeStudy.claims(None)})
    table = [line for line in lines if line.startswith("| C") or line.startswith("| E")]
    assert [row.split("|")[1].strip().split()[0] for row in table] == list(CLAIMS)
    assert "| C5 |" in lines[4 + 4] and "confirmed" in lines[4 + 4] and "order 1.02" in lines[4 + 4]
    assert any(row.startswith("| E1 (sod) |") and "partly" in row for row in table)
    assert sum("not measured" in row for row in table) == len(CLAIMS) - 2


def test_report_is_written_with_index_and_sections(tmp_path):
    path = write_report(StudyOptions(quick=True, out=tmp_path), studies=[("fake", _FakeStudy)])
    text = path.read_text()
    assert "QUICK" in text and "## fake" in text and "| E4 |" in text and "confirmed" in text
