"""The latest result of a benchmark: printed as JSON and written atomically to
tools/bench-results/<name>.json (git keeps the history)."""
import json
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def write(name, result):
    text = json.dumps(result, indent=1)
    print(text)
    out = os.path.join(ROOT, "tools", "bench-results", name + ".json")
    with open(out + ".tmp", "w") as f:
        f.write(text + "\n")
    os.replace(out + ".tmp", out)
