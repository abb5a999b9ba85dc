"""Helper module: a 95 % Student-t interval over seeds and an atomically written Markdown table.

Shared by the analysis scripts beside it; the table goes to OUT/tables/NAME (a temporary name,
then renamed) and is printed."""
import math
import os

# Two-sided 95 % Student-t quantiles by degrees of freedom (1.96 beyond).
T95 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306, 9: 2.262, 10: 2.228}


def interval95(values):
    """(mean, low, high) of the mean over `values`; low and high are nan for one value."""
    v = [float(x) for x in values]
    m = sum(v) / len(v)
    if len(v) < 2:
        return m, float("nan"), float("nan")
    sd = math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1))
    h = T95.get(len(v) - 1, 1.96) * sd / math.sqrt(len(v))
    return m, m - h, m + h


def writeTable(out, name, lines):
    text = "\n".join(lines)
    os.makedirs(f"{out}/tables", exist_ok=True)
    path = f"{out}/tables/{name}"
    with open(path + ".tmp", "w") as fh:
        fh.write(text + "\n")
    os.replace(path + ".tmp", path)
    print(text)
