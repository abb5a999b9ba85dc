#!/usr/bin/env python3
"""Train one COLMAP dataset in several world frames (moved, scaled) with one or more saresgs binaries.

The same dataset in six world frames and a control, trained by each binary given.

x' = s x + d is applied to the points and camera centres (rotations, intrinsics and images
unchanged), as COLMAP's model_transformer or a georeference does. Each frame is written as
a COLMAP text model beside links to the images and to the manifest of a `saresgs scene`
folder (its split and background; no depth maps, so every frame, the first one too, is
the same COLMAP dataset but for the frame), then
`saresgs train --dataset F --iterations N --seed 0` (or `saresgs active --method M`) runs
on it and the test PSNR (active: the final fit's, and the selected views) is printed as a
Markdown table, one column per binary.

    python3 scripts/experiments/frame_trials.py DATASET OUT --bin build/apps/saresgs [--bin OLD] [--iterations 300]
    python3 scripts/experiments/frame_trials.py DATASET OUT --bin build/apps/saresgs --active fisher --active-args '--max-views 10'


DATASET holds images/ and sparse/0/*.txt (what `saresgs scene` writes).
"""
import argparse
import json
import os
import subprocess
import sys

# Each frame is a list of similarities (s, d) applied in turn. The last one is a control:
# moved 1e6 away and back, so the file is in the original frame (no frame change at all)
# but holds every coordinate only to a double's resolution at 1e6, as the moved file does.
FRAMES = [
    ("as made", [(1.0, (0.0, 0.0, 0.0))]),
    ("translated by (1e5, -5e4, 3e4)", [(1.0, (1e5, -5e4, 3e4))]),
    ("translated by (1e6, 1e6, 0)", [(1.0, (1e6, 1e6, 0.0))]),
    ("scaled by 1e3 (millimetres)", [(1e3, (0.0, 0.0, 0.0))]),
    ("scaled by 1e-3 (kilometres)", [(1e-3, (0.0, 0.0, 0.0))]),
    ("scaled by 37.3, translated by (-123456.789, 4.2e5, 17.5)", [(37.3, (-123456.789, 4.2e5, 17.5))]),
    ("control: as made, moved by (1e6, 1e6, 0) and back", [(1.0, (1e6, 1e6, 0.0)), (1.0, (-1e6, -1e6, 0.0))]),
]


def quat_to_matrix(w, x, y, z):
    n = (w * w + x * x + y * y + z * z) ** 0.5
    w, x, y, z = w / n, x / n, y / n, z / n
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]


def transform_images(lines, s, d):
    out, header_done, expect_pose = [], False, True
    for line in lines:
        if line.startswith("#"):
            out.append(line)
            continue
        if expect_pose:
            f = line.split()
            qw, qx, qy, qz = map(float, f[1:5])
            t = list(map(float, f[5:8]))
            R = quat_to_matrix(qw, qx, qy, qz)
            # centre c = -R^T t; c' = s c + d; t' = -R c'
            c = [-sum(R[r][k] * t[r] for r in range(3)) for k in range(3)]
            c2 = [s * c[k] + d[k] for k in range(3)]
            t2 = [-sum(R[r][k] * c2[k] for k in range(3)) for r in range(3)]
            f[5:8] = [repr(v) for v in t2]
            out.append(" ".join(f) + "\n")
        else:
            out.append(line)
        expect_pose = not expect_pose
    return out


def transform_points(lines, s, d):
    out = []
    for line in lines:
        if line.startswith("#") or not line.strip():
            out.append(line)
            continue
        f = line.split()
        f[1:4] = [repr(s * float(f[1 + k]) + d[k]) for k in range(3)]
        out.append(" ".join(f) + "\n")
    return out


def write_frame(src, dst, steps):
    os.makedirs(os.path.join(dst, "sparse", "0"), exist_ok=True)
    sp = os.path.join(src, "sparse", "0")
    with open(os.path.join(sp, "cameras.txt")) as f:
        cams = f.read()
    with open(os.path.join(sp, "images.txt")) as f:
        images = f.readlines()
    with open(os.path.join(sp, "points3D.txt")) as f:
        points = f.readlines()
    for s, d in steps:
        images = transform_images(images, s, d)
        points = transform_points(points, s, d)
    out = os.path.join(dst, "sparse", "0")
    with open(os.path.join(out, "cameras.txt"), "w") as f:
        f.write(cams)
    with open(os.path.join(out, "images.txt"), "w") as f:
        f.writelines(images)
    with open(os.path.join(out, "points3D.txt"), "w") as f:
        f.writelines(points)
    # The manifest of a `saresgs scene` folder carries the split and the background; its
    # cameras are the original frame's, which the loader only uses to rebuild the ground
    # truth of a dataset left in that frame.
    manifest = os.path.join(src, "manifest.json")
    if os.path.isfile(manifest) and not os.path.lexists(os.path.join(dst, "manifest.json")):
        os.symlink(os.path.abspath(manifest), os.path.join(dst, "manifest.json"))
    link = os.path.join(dst, "images")
    if not os.path.lexists(link):
        os.symlink(os.path.abspath(os.path.join(src, "images")), link)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dataset")
    ap.add_argument("out")
    ap.add_argument("--bin", action="append", required=True, help="a saresgs binary (repeat for several)")
    ap.add_argument("--iterations", type=int, default=300)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--active", metavar="METHOD", help="run `saresgs active --method METHOD` instead of train")
    ap.add_argument("--active-args", default="", help="more options for active, e.g. '--max-views 10'")
    a = ap.parse_args()
    if not os.path.isfile(os.path.join(a.dataset, "sparse", "0", "images.txt")):
        sys.exit(f"{a.dataset}: expected a COLMAP text model in sparse/0 (images.txt)")
    rows = []
    for k, (name, steps) in enumerate(FRAMES):
        frame_dir = os.path.join(a.out, f"frame{k}")
        write_frame(a.dataset, frame_dir, steps)
        row = [name]
        for b, binary in enumerate(a.bin):
            run_dir = os.path.join(a.out, f"frame{k}_bin{b}")
            if a.active:
                cmd = [binary, "active", "--dataset", frame_dir, "--out", run_dir, "--method", a.active, "--seed", "0"]
                cmd += a.active_args.split()
            else:
                cmd = [binary, "train", "--dataset", frame_dir, "--out", run_dir, "--iterations", str(a.iterations),
                       "--seed", "0"]
            if a.threads:
                cmd += ["--threads", str(a.threads)]
            p = subprocess.run(cmd, capture_output=True, text=True)
            if p.returncode != 0:
                row.append(f"failed (rc {p.returncode})")
                print(p.stderr[-2000:], file=sys.stderr)
                continue
            with open(os.path.join(run_dir, "results.json")) as f:
                r = json.load(f)
            if a.active:
                fit = r.get("final_fit") or r
                row.append(f"{fit['psnr']:.2f} dB, views {' '.join(v.split('.')[0] for v in r['selected_views'])}")
            else:
                row.append(f"{r['psnr']:.2f} dB ({r['gaussians']} Gaussians)")
        rows.append(row)
        print(" | ".join(row), file=sys.stderr, flush=True)
    print("| frame | " + " | ".join(a.bin) + " |")
    print("|---|" + "---|" * len(a.bin))
    for row in rows:
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
