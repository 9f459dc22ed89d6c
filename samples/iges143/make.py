#!/usr/bin/env python3
"""IGES 143 Bounded Surfaces with 141 Boundaries, made from FreeCAD's 144 parts.

Open CASCADE (and so FreeCAD) writes trimmed faces as 144 Trimmed Surfaces with 142 Curve
on a Parametric Surface boundaries; no writer at hand writes 143. This script rewrites each
144 of a FreeCAD part file as a 143 (TYPE, SPTR, N, BDPT: the outer 142 first, then the
inner ones) and each 142 as a 141 Boundary (TYPE, PREF, SPTR, N = 1, CRVPT = the 142's
model-space curve, SENSE = 1, K, PSCPT = its parameter-space curve when it has one), IGES
5.3 types 141 and 143. Every other entity, the Directory
Entry fields other than the type, parameter pointer and line count, and the Start and Global
sections are kept as they are.

    python3 samples/iges143/make.py
"""

from pathlib import Path

HERE = Path(__file__).resolve().parent
PARTS = HERE.parent / "freecad" / "parts"
FILES = ["box_fillet_chamfer_hole.igs", "flange.igs", "sphere_cap.igs", "trimmed_face.igs"]


def section(lines, letter):
    return [l for l in lines if len(l) >= 73 and l[72] == letter]


def params(p_lines):
    """DE pointer -> the entity's parameter text (columns 1-64 joined)."""
    out = {}
    for l in p_lines:
        de = int(l[65:72])
        out.setdefault(de, []).append(l[:64].rstrip())
    return {de: "".join(parts) for de, parts in out.items()}


def rewrite(text):
    lines = text.splitlines()
    s, g, d, p = (section(lines, c) for c in "SGDP")
    par = params(p)
    kinds = {}
    for i in range(0, len(d), 2):
        kinds[i + 1] = int(d[i][0:8])
    new = {}
    for de, t in kinds.items():
        f = par[de].rstrip(";").split(",")
        if t == 144:
            pts, n1, n2, pto = int(f[1]), int(f[2]), int(f[3]), int(f[4])
            bounds = ([pto] if n1 and pto else []) + [int(x) for x in f[5 : 5 + n2]]
            given = all(int(par[b].split(",")[3]) != 0 for b in bounds)
            new[de] = ["143", str(int(given)), str(pts), str(len(bounds))] + [
                str(b) for b in bounds
            ]
        elif t == 142:
            _, sptr, bptr, cptr, pref = (int(x) for x in f[1:6])
            k = [str(bptr)] if bptr else []
            new[de] = ["141", str(int(bool(bptr))), str(pref), str(sptr), "1", str(cptr),
                       "1", str(len(k))] + k
    # The P section again: rewritten entities packed 64 columns a line, the others as
    # they were.
    out_p, starts = [], {}
    for de in sorted(kinds):
        starts[de] = len(out_p) + 1
        if de in new:
            tokens = new[de]
            line = ""
            for i, tok in enumerate(tokens):
                tok += ";" if i == len(tokens) - 1 else ","
                if len(line) + len(tok) > 64:
                    out_p.append((line, de))
                    line = ""
                line += tok
            out_p.append((line, de))
        else:
            out_p.extend((l[:64], de) for l in p if int(l[65:72]) == de)
    p_lines = [f"{data:<64} {de:>7}P{k + 1:07d}" for k, (data, de) in enumerate(out_p)]
    d_lines = []
    for i in range(0, len(d), 2):
        de = i + 1
        a, b = d[i], d[i + 1]
        count = sum(1 for _, x in out_p if x == de)
        t = "143" if kinds[de] == 144 else "141" if kinds[de] == 142 else a[0:8].strip()
        a = f"{t:>8}{starts[de]:>8}" + a[16:]
        b = f"{t:>8}" + b[8:24] + f"{count:>8}" + b[32:]
        d_lines += [a, b]
    t_line = f"S{len(s):07d}G{len(g):07d}D{len(d_lines):07d}P{len(p_lines):07d}"
    t_line = f"{t_line:<72}T0000001"
    return "\n".join(s + g + d_lines + p_lines + [t_line]) + "\n"


def main():
    for name in FILES:
        text = (PARTS / name).read_text()
        out = HERE / name.replace(".igs", "_143.igs")
        out.write_text(rewrite(text))
        print(out.relative_to(HERE.parent.parent))


if __name__ == "__main__":
    main()
