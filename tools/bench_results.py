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


def machine():
    """What the result was measured on: platform, logical CPUs, the load at the end."""
    import platform
    return {"platform": platform.platform(), "cpus": os.cpu_count(),
            "load_average_1min_at_end": os.getloadavg()[0]}


def publish(name, result, to_file):
    """`write` when `to_file`, else print the JSON only (a tool's `--no-file`)."""
    if to_file:
        write(name, result)
    else:
        print(json.dumps(result, indent=1))
