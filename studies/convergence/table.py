"""Print the markdown table of every committed convergence study.

    python studies/convergence/table.py

reads ``results/*/rates.json`` beside this script (as written by
``adhcontact converge``) and prints one row per study: the observed
least-squares rates against the theoretical 1 of docs/scheme.md.
"""

import json
from pathlib import Path

HERE = Path(__file__).resolve().parent


def fmt(value, spec=".3f"):
    return "—" if value is None else format(value, spec)


def main():
    print("| case | study | reference | levels | rate ‖ε(u−u_h)‖ | rate ‖β−β_h‖ | "
          "rate E | E at the finest level | time of all levels |")
    print("|---|---|---|---|---|---|---|---|---|")
    for path in sorted(HERE.glob("results/*/rates.json")):
        doc = json.loads(path.read_text())
        case, param = path.parent.name.rsplit("-", 1)
        levels = doc["levels"]
        ref = doc.get("reference", {})
        kind = ref.get("kind", "?")
        if kind == "fine":
            kind = f"fine (refine {ref.get('refine')}, {ref.get('steps')} steps)"
        r = doc["rates"]
        seconds = sum(level["seconds"] for level in levels)
        print(f"| {case} | {param} | {kind} | {len(levels)} | {fmt(r['u'])} | "
              f"{fmt(r['beta'])} | **{fmt(r['E'])}** | {fmt(levels[-1]['E'], '.2e')} | "
              f"{seconds:.1f} s |")


if __name__ == "__main__":
    main()
