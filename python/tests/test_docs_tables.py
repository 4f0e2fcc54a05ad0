"""tools/docs-tables: the tables of results in the documentation against the code that computes them.

The quick table of docs/results.md is compared with a fresh `asperity run --quick` of the binary
$ASPERITY_CLI (`.ci/test` builds it and sets the variable); the script's own rules are tested on
small hand-made results.json files and, for `check`, in a temporary git repository.
"""

import importlib.machinery
import importlib.util
import json
import os
import re
import shutil
import stat
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TOOL = ROOT / "tools" / "docs-tables"
RESULTS_MD = ROOT / "docs" / "results.md"


def tool_module():
    loader = importlib.machinery.SourceFileLoader("docs_tables", str(TOOL))
    spec = importlib.util.spec_from_loader("docs_tables", loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


def tables(*args, cwd=None):
    """Run the script with this interpreter: (exit status, stdout, stderr)."""
    done = subprocess.run([sys.executable, str(TOOL), *map(str, args)], capture_output=True, text=True, cwd=cwd)
    return done.returncode, done.stdout, done.stderr


DECADES = [1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1]


def row(load, topography, law, drop, points, sharing="equal"):
    """A row of results.json with every field of `Row` (src/study/mod.rs)."""
    return {
        "load_n": load,
        "topography": topography,
        "law": law,
        "plastic": False,
        "sharing": sharing,
        "mu_s": 0.6,
        "mu_d": 0.4,
        "contact_points": points,
        "patches": 1,
        "contact_fraction": 1e-3,
        "max_pressure_pa": 1e9,
        "edge_load_fraction": 0.0,
        "load_above_hardness_fraction": None,
        "static_coefficient": 0.4 * drop,
        "dynamic_coefficient": 0.4,
        "friction_drop": drop,
        "critical_count": 1,
        "critical_normal_fraction": 0.5,
        "critical_friction_fraction": 0.5,
        "pre_sliding_count": 0,
        "pre_sliding_normal_fraction": 0.0,
        "pre_sliding_friction_fraction": 0.0,
        "subcritical_count": 1,
        "subcritical_normal_fraction": 0.5,
        "subcritical_friction_fraction": 0.5,
        "weakening_count": None,
        "weakening_normal_fraction": None,
        "weakening_friction_fraction": None,
        "iterations": 10,
        "seconds": 0.01,
        "slide_iterations": None,
        "slide_seconds": None,
        "adhesive_force_n": None,
        "friction_drop_total_load": None,
    }


def tiny_results(commit="0123456789ab", sharings=("equal",)):
    """Two balls × two laws × the seven decades; ball-2 has one more element and a lower drop."""
    rows = []
    for sharing in sharings:
        for ball, extra in (("ball-1", 0), ("ball-2", 1)):
            for law, base in (("hold 100 s", 1.5), ("hold 10 s", 1.25)):
                for i, load in enumerate(DECADES):
                    drop = 1 + (base - 1) / (1 + i) - extra * 0.001 * i - (0.002 if sharing == "elastic" else 0)
                    rows.append(row(load, ball, law, drop, 1 + 10 * i + extra * (i > 0), sharing))
    return {"asperity_version": "0.2.0", "commit": commit, "rows": rows}


def write_json(path, data):
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


DOC = (
    "# A page\r\n"
    "Text before, with µ and – and trailing spaces   \n"
    "\n"
    "<!-- docs-tables: default begin -->\n"
    "stale text\n"
    "<!-- docs-tables: default end -->\n"
    "\n"
    "```markdown\n"
    "<!-- docs-tables: quick begin -->\n"
    "```\n"
    "Text after, no newline at the end"
)


def test_render_rewrites_the_region_and_leaves_every_other_byte(tmp_path):
    results = write_json(tmp_path / "results.json", tiny_results())
    doc = tmp_path / "page.md"
    doc.write_bytes(DOC.encode("utf-8"))
    doc.chmod(0o640)
    rc, out, err = tables("render", "default", results, doc, "--date", "2026-12-04")
    assert rc == 0, err
    text = doc.read_bytes().decode("utf-8")
    begin, end = "<!-- docs-tables: default begin -->\n", "<!-- docs-tables: default end -->\n"
    before, rest = text.split(begin)
    inside, after = rest.split(end)
    assert before + begin == DOC.split("stale text\n")[0]
    assert end + after == DOC.split("stale text\n")[1]
    assert stat.S_IMODE(doc.stat().st_mode) == 0o640
    assert "\r" not in inside, "the region's lines end as its begin marker's line does"
    lines = inside.splitlines()
    assert lines[1] == '| load | contact elements | friction drop, "hold 100 s" | friction drop, "hold 10 s" |'
    assert lines[3] == "| 0.1 µN | 1 | 1.5000 | 1.2500 |"
    assert lines[4] == "| 1 µN | 11–12 | 1.2490–1.2500 | 1.1240–1.1250 |"
    assert lines[9] == "| 100 mN | 61–62 | 1.0654–1.0714 | 1.0297–1.0357 |"
    assert lines[-1] == "*Computed by `asperity run` with asperity 0.2.0 (commit 0123456789ab), 2026-12-04.*"
    assert not list(tmp_path.glob(".page.md.*")), "the temporary file is left behind"
    # A second render changes nothing.
    rc, out, err = tables("render", "default", results, doc, "--date", "2026-12-04")
    assert rc == 0 and "unchanged" in out and doc.read_bytes().decode("utf-8") == text


def test_the_quick_table_lists_every_load_and_the_elastic_table_both_sharings(tmp_path):
    both = tiny_results(sharings=("equal", "elastic"))
    both["rows"] = [r for r in both["rows"] if r["load_n"] != 1e-5 or r["sharing"] == "equal"]
    quick = tiny_results()
    quick["rows"] = [r for r in quick["rows"] if r["load_n"] != 1e-5] + [
        dict(r, load_n=3.16227766017e-5) for r in quick["rows"] if r["load_n"] == 1e-5
    ]
    doc = tmp_path / "page.md"
    doc.write_text(
        "<!-- docs-tables: elastic begin -->\n<!-- docs-tables: elastic end -->\n"
        "<!-- docs-tables: quick begin -->\n<!-- docs-tables: quick end -->\n",
        encoding="utf-8",
    )
    rc, _, err = tables("render", "elastic", write_json(tmp_path / "e.json", both), doc)
    assert rc == 0, err
    rc, _, err = tables("render", "quick", write_json(tmp_path / "q.json", quick), doc)
    assert rc == 0, err
    text = doc.read_text(encoding="utf-8")
    assert '| load | contact elements | friction drop, "hold 100 s": equal → elastic |' in text
    assert "| 0.1 mN | 31–32 | 1.1220–1.1250 → 1.1200–1.1230 | 1.0595–1.0625 → 1.0575–1.0605 |" in text
    assert "| 10 µN | 21–22 | 1.1647–1.1667 → – | 1.0813–1.0833 → – |" in text
    assert "| 31.6228 µN | 21–22 |" in text and "| 10 µN |" in text.split("quick begin")[0]
    assert "*Computed by `asperity run --quick` with asperity 0.2.0" in text
    # The elastic table needs two sharings.
    rc, _, err = tables("render", "elastic", tmp_path / "q.json", doc)
    assert rc == 2 and "one sharing only" in err


def test_the_balls_table_gives_each_topographys_contact_at_three_loads(tmp_path):
    results = tiny_results()
    for r in results["rows"]:
        r["patches"] = 2 + (r["topography"] == "ball-2")
        r["max_pressure_pa"] = 1e9 * (1 + 10 * r["load_n"]) + 0.5e9 * (r["topography"] == "ball-2")
    doc = tmp_path / "page.md"
    doc.write_text("<!-- docs-tables: balls begin -->\n<!-- docs-tables: balls end -->\n", encoding="utf-8")
    rc, _, err = tables("render", "balls", write_json(tmp_path / "r.json", results), doc)
    assert rc == 0, err
    text = doc.read_text(encoding="utf-8")
    assert "| topography | 0.1 mN: elements, patches | 1 mN: elements, patches | 10 mN: elements, patches |" in text
    assert "| ball-1 | 31, 2 | 41, 2 | 51, 2 | 1.0 / 1.0 / 1.1 GPa |" in text
    assert "| ball-2 | 32, 3 | 42, 3 | 52, 3 | 1.5 / 1.5 / 1.6 GPa |" in text
    # A run without 10 mN cannot describe the balls there.
    results["rows"] = [r for r in results["rows"] if r["load_n"] != 1e-2]
    rc, _, err = tables("render", "balls", write_json(tmp_path / "s.json", results), doc)
    assert rc == 2 and "10 mN" in err


def test_an_unclosed_region_is_refused_and_nothing_written(tmp_path):
    results = write_json(tmp_path / "results.json", tiny_results())
    for broken in (
        "a\n<!-- docs-tables: default begin -->\nb\n",
        "<!-- docs-tables: default begin -->\n<!-- docs-tables: quick begin -->\n<!-- docs-tables: quick end -->\n",
        "<!-- docs-tables: default end -->\n",
        "<!-- docs-tables: default begin -->\n<!-- docs-tables:default end -->\n",
    ):
        doc = tmp_path / "page.md"
        doc.write_text(broken, encoding="utf-8")
        rc, out, err = tables("render", "default", results, doc)
        assert rc == 2, (broken, out, err)
        assert err.startswith("docs-tables: ") and err.count("\n") == 1, err
        assert doc.read_text(encoding="utf-8") == broken
    doc.write_text("a\n<!-- docs-tables: default begin -->\nb\n", encoding="utf-8")
    rc, _, err = tables("check", doc)
    assert rc == 2 and "'default' is not closed" in err


@pytest.mark.parametrize("commit", ["0123456789ab-modified", "unknown"])
def test_results_of_an_uncommitted_build_are_refused(tmp_path, commit):
    results = write_json(tmp_path / "results.json", tiny_results(commit=commit))
    doc = tmp_path / "page.md"
    doc.write_text("<!-- docs-tables: default begin -->\n<!-- docs-tables: default end -->\n", encoding="utf-8")
    rc, _, err = tables("render", "default", results, doc)
    assert rc == 2 and f"'{commit}'" in err and "--allow-modified" in err, err
    assert "Computed" not in doc.read_text(encoding="utf-8")
    rc, _, err = tables("render", "default", results, doc, "--allow-modified")
    assert rc == 0, err
    assert f"(commit {commit})" in doc.read_text(encoding="utf-8")


def test_a_results_json_not_of_the_shape_is_refused(tmp_path):
    doc = tmp_path / "page.md"
    doc.write_text("<!-- docs-tables: default begin -->\n<!-- docs-tables: default end -->\n", encoding="utf-8")
    good = tiny_results()
    no_drop = json.loads(json.dumps(good))
    del no_drop["rows"][3]["friction_drop"]
    text_load = json.loads(json.dumps(good))
    text_load["rows"][0]["load_n"] = "1 mN"
    no_decade = json.loads(json.dumps(good))
    no_decade["rows"] = [r for r in no_decade["rows"] if r["load_n"] != 1e-3]
    for data, reason in (
        (good["rows"], "an object"),
        ({"commit": "0123456789ab", "rows": good["rows"]}, "'asperity_version'"),
        (dict(good, rows=[]), "'rows' missing or empty"),
        (no_drop, "rows[3] lacks 'friction_drop'"),
        (text_load, "rows[0].load_n"),
        (no_decade, "no load at 1 mN"),
    ):
        rc, _, err = tables("render", "default", write_json(tmp_path / "r.json", data), doc)
        assert rc == 2 and reason in err and err.count("\n") == 1, (reason, err)
    (tmp_path / "r.json").write_text("{not json", encoding="utf-8")
    rc, _, err = tables("compare", "default", tmp_path / "r.json", doc)
    assert rc == 2 and "not JSON" in err


def test_compare_finds_a_changed_number_and_ignores_the_provenance_line(tmp_path):
    results = write_json(tmp_path / "results.json", tiny_results())
    doc = tmp_path / "page.md"
    doc.write_text("<!-- docs-tables: default begin -->\n<!-- docs-tables: default end -->\n", encoding="utf-8")
    rc, out, err = tables("compare", "default", results, doc)
    assert rc == 1 and "differs" in out, (out, err)
    assert tables("render", "default", results, doc, "--date", "2026-01-01")[0] == 0
    rc, out, err = tables("compare", "default", results, doc)
    assert rc == 0 and "agrees" in out, (out, err)
    text = doc.read_text(encoding="utf-8")
    doc.write_text(text.replace("2026-01-01", "2027-02-02").replace("0123456789ab", "ba9876543210"), encoding="utf-8")
    assert tables("compare", "default", results, doc)[0] == 0
    doc.write_text(text.replace("1.2490–1.2500", "1.2490–1.2501"), encoding="utf-8")
    rc, out, _ = tables("compare", "default", results, doc)
    assert rc == 1 and "-| 1 µN | 11–12 | 1.2490–1.2501 |" in out and "+| 1 µN | 11–12 | 1.2490–1.2500 |" in out


def git(repo, *args):
    env = dict(
        os.environ,
        GIT_AUTHOR_NAME="t",
        GIT_AUTHOR_EMAIL="t@example.org",
        GIT_COMMITTER_NAME="t",
        GIT_COMMITTER_EMAIL="t@example.org",
        GIT_CONFIG_GLOBAL=os.devnull,
        GIT_CONFIG_NOSYSTEM="1",
    )
    done = subprocess.run(["git", "-C", str(repo), *args], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def test_check_says_a_table_is_older_than_a_later_solver_change(tmp_path):
    if shutil.which("git") is None:
        pytest.skip("git is not installed")
    repo = tmp_path / "repo"
    (repo / "src" / "contact").mkdir(parents=True)
    (repo / "docs").mkdir()
    git(repo, "init", "-q")
    (repo / "src" / "contact" / "solver.rs").write_text("// one\nfn a() {}\n", encoding="utf-8")
    page = repo / "docs" / "results.md"
    page.write_text("# Results\n<!-- docs-tables: default begin -->\n<!-- docs-tables: default end -->\n", encoding="utf-8")
    git(repo, "add", "-A")
    git(repo, "commit", "-q", "-m", "the solver")
    computed = git(repo, "rev-parse", "--short=12", "HEAD")

    rc, out, _ = tables("check", page)
    assert rc == 0 and "never rendered" in out, out
    assert tables("check", "--strict", page)[0] == 0

    results = write_json(tmp_path / "results.json", tiny_results(commit=computed))
    assert tables("render", "default", results, page, "--date", "2026-12-04")[0] == 0
    git(repo, "commit", "-q", "-am", "the table")
    (repo / "README.md").write_text("prose\n", encoding="utf-8")
    git(repo, "add", "-A")
    git(repo, "commit", "-q", "-m", "prose only")
    rc, out, _ = tables("check", page)
    assert rc == 0 and f"computed at commit {computed}" in out and "current" in out and "older" not in out, out
    assert tables("check", "--strict", page)[0] == 0

    # A comment cannot change a number: the table stays current.
    (repo / "src" / "contact" / "solver.rs").write_text("/// two\nfn a() {}\n", encoding="utf-8")
    git(repo, "commit", "-q", "-am", "a comment")
    rc, out, _ = tables("check", page)
    assert rc == 0 and "current" in out and "older" not in out, out
    # Nor can reformatting (rustfmt splitting a list over lines, with its trailing comma).
    (repo / "src" / "contact" / "solver.rs").write_text("/// two\nfn a(\n    x: u8,\n) {}\n", encoding="utf-8")
    git(repo, "commit", "-q", "-am", "an argument")
    (repo / "src" / "contact" / "solver.rs").write_text("/// two\nfn a(x: u8) {}\n", encoding="utf-8")
    git(repo, "commit", "-q", "-am", "reformatted")
    rc, out, _ = tables("check", page)
    assert rc == 0 and "older" in out and "an argument" in out and "reformatted" not in out, out

    (repo / "src" / "contact" / "solver.rs").write_text("/// two\nfn a(x: u8) { b() }\n", encoding="utf-8")
    git(repo, "commit", "-q", "-am", "a faster solver")
    newest = git(repo, "rev-parse", "--short", "HEAD")
    rc, out, _ = tables("check", page)
    assert rc == 0 and "older than the solver" in out and newest in out and "a faster solver" in out, out
    assert "asperity run" in out and "render default" in out, out
    rc, out, _ = tables("check", "--strict", page)
    assert rc == 1 and "older than the solver" in out


def test_the_script_knows_every_field_of_a_row():
    source = (ROOT / "src" / "study" / "mod.rs").read_text(encoding="utf-8")
    body = re.search(r"pub struct Row \{(.*?)\n\}", source, re.S).group(1)
    fields = dict(re.findall(r"pub (\w+): ([^,\n]+),", body))
    module = tool_module()
    optional = {name for name, kind in fields.items() if kind.startswith("Option<")} | {"sharing"}
    assert set(module.ROW_FIELDS) == set(fields) - optional
    assert set(module.OPTIONAL_ROW_FIELDS) == optional


def test_loads_print_with_si_prefixes():
    module = tool_module()
    labels = [module.load_label(x) for x in DECADES + [3.16227766017e-05, 9.999999999999999e-5, 1.0, 2e-10]]
    assert labels == ["0.1 µN", "1 µN", "10 µN", "0.1 mN", "1 mN", "10 mN", "100 mN", "31.6228 µN", "0.1 mN", "1 N", "0.2 nN"]
    # The summary's columns are as `asperity run` prints them.
    assert [module.show_force(x) for x in module.SUMMARY_LOADS] == ["100 µN", "1 mN", "10 mN", "100 mN"]


def test_the_quick_table_in_the_docs_is_what_asperity_run_quick_gives(tmp_path):
    """Fails when the code's numbers drift from docs/results.md: rerun `asperity run --quick` and
    `tools/docs-tables render quick results/results.json docs/results.md`."""
    cli = os.environ.get("ASPERITY_CLI")
    if not cli:
        pytest.skip("ASPERITY_CLI is not set: it names the asperity binary to run (.ci/test sets it)")
    assert Path(cli).is_file(), f"ASPERITY_CLI={cli} does not exist"
    out = tmp_path / "quick"
    done = subprocess.run([cli, "run", "--quick", "--out", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    rc, stdout, stderr = tables("compare", "quick", out / "results.json", RESULTS_MD)
    assert rc == 0, (
        stdout + stderr + "\nThe code's numbers changed: if that is meant, run `asperity run --quick --out DIR` "
        "and `tools/docs-tables render quick DIR/results.json docs/results.md`"
    )
    # The region holds the table (all seven loads), so the comparison compared numbers.
    module = tool_module()
    [region] = [r for r in module.regions(RESULTS_MD, module.read_markdown(RESULTS_MD)) if r.name == "quick"]
    assert len(region.table()) == 2 + 7, region.table()
    # And one number changed in it is found.
    changed = tmp_path / "results.md"
    text = RESULTS_MD.read_text(encoding="utf-8")
    last = region.table()[-1]
    number = re.search(r"\d\.\d{4}", last).group(0)
    wrong = f"{number[:-1]}{(int(number[-1]) + 1) % 10}"
    changed.write_text(text.replace(last, last.replace(number, wrong, 1)), encoding="utf-8")
    rc, stdout, _ = tables("compare", "quick", out / "results.json", changed)
    assert rc == 1 and wrong in stdout, stdout
