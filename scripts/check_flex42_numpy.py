#!/usr/bin/env python3
"""NASA 42's flexible-body file and node file, read as 42 reads them, then checked.

An independent reader, written from 42's own C source and nothing else: NASA 42, upstream
https://github.com/ericstoneking/42 commit 11e3cc39ca6f031e6d071d51d7a6c6f85afb83f0, the copy
in /work/shared/nasa42 (Source/42init.c: InitFlexModes, lines 1150-1541, reads the flex file;
InitNodes, lines 1543-1570, reads the node file). Every read below names the 42init.c line
whose fscanf it replays. The fscanf calls themselves are replayed by a small emulation of C's
scanf (class CStream): the same directives, the same whitespace skipping, the same silent
failures. 42 never checks fscanf's return value, so a file 42 would misread is not refused by
42: it is read wrong. This reader reports, as a failure, everything that makes 42 read a value
from somewhere other than where the file's layout puts it:
  * a conversion that fails (42 would keep the previous or zero value and read on);
  * a value line without text after its values: 42's " %[^\n]" (the comment) then skips the
    newline and swallows the whole next line, so every later read is shifted by a line;
  * a fscanf call whose conversions span more than one line;
  * a comment longer than 42's 80-byte buffers (junk[80], NodeType.comment[80]): an overflow;
  * a file name longer than 42's 40-byte FlexFileName/NodeFileName;
  * the range checks 42 makes (exit(1) in 42) and a node index 42 would use out of range.

Then, from the parsed arrays only, the identities every correct flex body satisfies:
  * Mf = I (mass-normalised modes), symmetric;
  * Kf symmetric, diagonal, non-negative (omega^2 of modes orthogonal in M and K);
  * Cf symmetric, positive semi-definite (dissipative);
  * N_abpq = N_baqp and the 3Nf x 3Nf matrix [(a,p),(b,q)] -> N_abpq positive
    semi-definite (N is the Gram matrix of the mode-shape components, int Psi_ap Psi_bq dm);
  * sum_a N_aapq = Mf_pq (int Psi_p . Psi_q dm is the modal mass);
  * Hf = the antisymmetric part of L (Hf_p = int r x Psi_p dm, L_abp = int Psi_ap r_b dm);
  * with the body's mass properties (--mass, --cm, --inertia-ref: 42 takes them from the
    spacecraft file, not from the flex file), the effective-mass bounds
    sum_p Pf_p Pf_p^T <= m I, sum_p Hf_p Hf_p^T <= J_O and, jointly,
    [Pf; Hf] Mf^-1 [Pf; Hf]^T <= M_O (the 6 x 6 rigid mass about the reference point) in the
    positive semi-definite sense, and the Gram matrix of {1, r, Psi_ap} over the body's mass
    (m, m c, int r r^T dm = tr(J_O)/2 I - J_O, Pf, L, N) positive semi-definite;
  * with --dtsim, 42's own step check (42init.c:1401-1409): pi/omega_p >= DTSIM.

Conventions 42's source fixes: Pf_p = int Psi_p dm and Hf_p = int r x Psi_p dm, because 42
builds the coupling of mode j with the body's rotation as HplusQeta = Hf + Qf eta
(42dynamics.c:1311-1322), which is int (r + u) x Psi_j dm only when
Qf(., j, k) = int Psi_k x Psi_j dm; 42 builds Qf(0,j,k) = N[2][1][j][k] - N[1][2][j][k]
(42init.c:1486), so N[a][b][p][q] = int Psi_ap Psi_bq dm. 42 uses only the symmetric part of
L (Rf enters only the quadratic form w^T Rf w, 42dynamics.c:1444-1476), so L's orientation is
the one the exporter documents (docs/export.md: L_ijp = int Psi_ip r_j dm).

Usage:
  check_flex42_numpy.py FLEX NODES --json OUT.json [--mass M --cm=X,Y,Z --inertia-ref=J11,...,J33]
                        [--rtol 1e-9] [--joints NG] [--dtsim DT]
Exit status 0 when every check passes, 1 on any failure (each printed), 2 on bad usage.
"""

import argparse
import json
import math
import os
import re
import sys

import numpy as np

# ---------------------------------------------------------------------------------------
# A replay of C's fscanf for the directives 42 uses: "%[^\n]", "%[\n]", "%[^\"]", "%ld",
# "%lf", "%s", white space (any amount, newlines included, possibly none) and literal
# characters. Semantics (C11 7.21.6.2): %[ does not skip white space and fails on an empty
# match; %ld, %lf and %s skip leading white space; a failure ends the call, leaving the input
# at the failing character. The caller never sees the failure in 42; here it is recorded.
# ---------------------------------------------------------------------------------------

_WS = " \t\n\v\f\r"
_DEC = re.compile(
    r"[+-]?(?:(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
    r"|0[xX](?:[0-9a-fA-F]+(?:\.[0-9a-fA-F]*)?|\.[0-9a-fA-F]+)(?:[pP][+-]?[0-9]+)?"
    r"|[iI][nN][fF](?:[iI][nN][iI][tT][yY])?|[nN][aA][nN](?:\([0-9A-Za-z_]*\))?)"
)
_INT = re.compile(r"[+-]?[0-9]+")
# Buffers of 42 that %[ and %s write into (Include/42types.h, 42init.c:1159 and 1547).
JUNK_BYTES = 80  # char junk[80]
COMMENT_BYTES = 80  # struct NodeType: char comment[80] (42types.h:49)
FILE_NAME_BYTES = 40  # struct BodyType: char NodeFileName[40], FlexFileName[40] (42types.h:116-117)


class ReadFailure(Exception):
    """The file is read differently by 42 than its layout says."""


class CStream:
    def __init__(self, text, name):
        self.s = text
        self.name = name
        self.pos = 0
        self.skipped_newlines = 1  # newlines the last white-space directive skipped
        self.newlines = [i for i, ch in enumerate(text) if ch == "\n"]

    def line_of(self, pos):
        # 1-based line number of a character offset
        lo, hi = 0, len(self.newlines)
        while lo < hi:
            mid = (lo + hi) // 2
            if self.newlines[mid] < pos:
                lo = mid + 1
            else:
                hi = mid
        return lo + 1

    def _skip_ws(self):
        start = self.pos
        while self.pos < len(self.s) and self.s[self.pos] in _WS:
            self.pos += 1
        return self.s.count("\n", start, self.pos)

    def fscanf(self, fmt, where):
        """Replays fscanf(infile, fmt, ...) of 42init.c:`where`; returns the converted values
        (the %[ conversions' strings included, the trailing %[\\n] excluded).

        Raises ReadFailure where 42 would read something else than one line's fields: a
        failed conversion (other than the trailing %[\\n], which always fails by design, the
        white space before it having taken every newline), a call spanning lines, an overflow.
        """
        out = []
        first_line = None
        tokens = _tokenize(fmt)
        if tokens[0].startswith("%[") and self.skipped_newlines > 1:
            # The previous call's trailing " " skipped blank lines: this %[ (a header or a
            # title) reads a later line than the one the layout puts it on.
            line = self.line_of(self.pos)
            raise ReadFailure(
                f"{self.name}:{line}: blank line before it: 42init.c:{where} (fscanf {fmt!r}) "
                f"reads line {line} where the layout has the blank line, and every later read "
                "is shifted"
            )
        for k, tok in enumerate(tokens):
            last = k == len(tokens) - 1
            if tok == " ":
                self.skipped_newlines = self._skip_ws()
                continue
            if tok in ("%ld", "%lf", "%s"):
                self._skip_ws()
            start = self.pos
            line = self.line_of(start)
            if tok == "%[\n]" and last:
                # Always fails: the " " before it has already consumed every newline.
                break
            if self.pos >= len(self.s):
                raise ReadFailure(
                    f"{self.name}: end of file where 42init.c:{where} reads {tok} "
                    f"(fscanf {fmt!r})"
                )
            if first_line is None:
                first_line = line
            elif line != first_line:
                raise ReadFailure(
                    f"{self.name}:{first_line}: 42init.c:{where} (fscanf {fmt!r}) reads {tok} "
                    f"from line {line}: line {first_line} lacks "
                    + (
                        "its text after the values (42 swallows the next line as the comment)"
                        if tok.startswith("%[")
                        else "a value"
                    )
                )
            if tok == "%ld":
                m = _INT.match(self.s, self.pos)
                if not m:
                    raise self._conv_fail(tok, fmt, where)
                out.append(int(m.group(0)))
                self.pos = m.end()
            elif tok == "%lf":
                m = _DEC.match(self.s, self.pos)
                if not m:
                    raise self._conv_fail(tok, fmt, where)
                t = m.group(0)
                # C: a decimal mantissa followed by an exponent marker without digits ("1e",
                # "1e+") is a matching failure (the longest prefix of a number is consumed)
                special = re.search(r"[xXiInN]", t) is not None
                if not special and self.s[m.end() : m.end() + 1] in ("e", "E"):
                    raise self._conv_fail(tok, fmt, where)
                out.append(_c_double(t))
                self.pos = m.end()
            elif tok == "%s":
                j = self.pos
                while j < len(self.s) and self.s[j] not in _WS:
                    j += 1
                out.append(self.s[self.pos : j])
                self.pos = j
            elif tok.startswith("%["):
                neg, chars = _scanset(tok)
                j = self.pos
                while j < len(self.s) and ((self.s[j] in chars) != neg):
                    j += 1
                if j == self.pos:
                    raise ReadFailure(
                        f"{self.name}:{line}: 42init.c:{where} (fscanf {fmt!r}): {tok} matches "
                        f"nothing at {self.s[self.pos:self.pos + 20]!r} (an empty comment or "
                        "line: 42's read stops there and every later read is shifted)"
                    )
                out.append(self.s[self.pos : j])
                self.pos = j
            else:  # a literal character
                if self.s[self.pos] != tok:
                    raise ReadFailure(
                        f"{self.name}:{line}: 42init.c:{where} (fscanf {fmt!r}) expects "
                        f"{tok!r}, finds {self.s[self.pos]!r}"
                    )
                self.pos += 1
        return out

    def _conv_fail(self, tok, fmt, where):
        line = self.line_of(self.pos)
        return ReadFailure(
            f"{self.name}:{line}: 42init.c:{where} (fscanf {fmt!r}): {tok} cannot convert "
            f"{self.s[self.pos:self.pos + 30]!r} (42 keeps the old value and reads on)"
        )

    def rest(self):
        return self.s[self.pos :]


def _tokenize(fmt):
    toks = []
    i = 0
    while i < len(fmt):
        c = fmt[i]
        if c in _WS:
            while i < len(fmt) and fmt[i] in _WS:
                i += 1
            toks.append(" ")
        elif c == "%":
            if fmt[i + 1] == "[":
                j = fmt.index("]", i + 3 if fmt[i + 2] in "^]" else i + 2)
                toks.append(fmt[i : j + 1])
                i = j + 1
            else:
                m = re.match(r"%(ld|lf|s)", fmt[i:])
                toks.append(m.group(0))
                i += len(m.group(0))
        else:
            toks.append(c)
            i += 1
    return toks


def _scanset(tok):
    body = tok[2:-1]
    neg = body.startswith("^")
    if neg:
        body = body[1:]
    return neg, body.replace("\\n", "\n").replace('\\"', '"')


def _c_double(t):
    tl = t.lower()
    if "x" in tl:
        sign = -1.0 if tl.startswith("-") else 1.0
        return sign * float.fromhex(tl.lstrip("+-"))
    if "nan" in tl:
        return float("nan")
    return float(t)


def _junk(stream, value, where, what="junk"):
    # %[^\n] into char junk[80] (42init.c:1159): 79 characters and the terminating zero
    if len(value.encode("latin-1")) > JUNK_BYTES - 1:
        raise ReadFailure(
            f"{stream.name}: 42init.c:{where}: a {len(value)}-character {what} overflows 42's "
            f"char junk[{JUNK_BYTES}]: {value[:40]!r}..."
        )


def read_line(stream, fmt, where):
    """One fscanf of 42 whose last two conversions are %[^\\n] (junk) and %[\\n]."""
    vals = stream.fscanf(fmt, where)
    _junk(stream, vals[-1], where)
    return vals[:-1]


# ---------------------------------------------------------------------------------------
# InitNodes, 42init.c:1543-1570
# ---------------------------------------------------------------------------------------


def read_nodes(text, name):
    st = CStream(text, name)
    read_line(st, "%[^\n] %[\n]", 1552)  # title
    read_line(st, "%[^\n] %[\n]", 1553)  # description
    (num_nodes,) = read_line(st, "%ld %[^\n] %[\n]", 1554)  # B->NumNodes
    if num_nodes < 0:
        raise ReadFailure(f"{name}: 42init.c:1554: NumNodes = {num_nodes} (calloc of a negative count)")
    read_line(st, "%[^\n] %[\n]", 1556)  # "Node Location, Comment" header
    pos = np.zeros((num_nodes, 3))
    comments = []
    for n in range(num_nodes):  # 42init.c:1557
        # 42init.c:1559: fscanf(infile,"%lf %lf %lf \"%[^\"]\" %[\n]", NomPosB[0..2], comment)
        x, y, z, comment = st.fscanf('%lf %lf %lf "%[^"]" %[\n]', 1559)
        if len(comment.encode("latin-1")) > COMMENT_BYTES - 1:
            raise ReadFailure(
                f"{name}: 42init.c:1559: node {n}'s comment ({len(comment)} characters) "
                f"overflows NodeType.comment[{COMMENT_BYTES}]"
            )
        pos[n] = (x, y, z)
        comments.append(comment)
    return {"num_nodes": num_nodes, "position": pos, "comment": comments, "unread": st.rest()}


# ---------------------------------------------------------------------------------------
# InitFlexModes, 42init.c:1150-1541
# ---------------------------------------------------------------------------------------


def read_flex(text, name, num_nodes, num_joints):
    # First pass (42init.c:1167-1198): the mode count only.
    st = CStream(text, name)
    read_line(st, "%[^\n] %[\n]", 1173)
    read_line(st, "%[^\n] %[\n]", 1174)
    (nf,) = read_line(st, "%ld %[^\n] %[\n]", 1176)  # B->Nf
    if nf < 0:
        raise ReadFailure(f"{name}: 42init.c:1176: Nf = {nf}")

    # Second pass (42init.c:1233-1509): from the top again.
    st = CStream(text, name)
    (title,) = st.fscanf("%[^\n] %[\n]", 1238)
    _junk(st, title, 1238, "title")
    read_line(st, "%[^\n] %[\n]", 1239)
    read_line(st, "%[^\n] %[\n]", 1240)  # the mode count's line, skipped this time

    # Initial modal states x, u (42init.c:1242-1250): "%lf %lf" into eta (x), xi (u)
    read_line(st, "%[^\n] %[\n]", 1243)
    eta = np.zeros(nf)
    xi = np.zeros(nf)
    for f in range(nf):
        eta[f], xi[f] = read_line(st, "%lf %lf %[^\n] %[\n]", 1245)

    assigned = {}

    def put(key, idx, value, where):
        # 42 assigns; a second entry overwrites the first silently. Ambiguous: a failure here.
        k = (key,) + tuple(idx)
        if k in assigned:
            raise ReadFailure(
                f"{name}: 42init.c:{where}: {key}{list(idx)} given twice "
                f"({assigned[k]} then {value}); 42 keeps the last"
            )
        assigned[k] = value

    # Joint node mode shapes (42init.c:1263-1316). The body's joints are in the spacecraft
    # file; a single flexible body has none (Ng = 0), so any entry is 42's exit(1) at 1271.
    read_line(st, "%[^\n] %[\n]", 1264)  # "Joint Node Mode Shapes"
    joint = {}
    for kind, hdr, cnt, ent in (("PSI", 1266, 1267, 1269), ("THETA", 1292, 1293, 1295)):
        read_line(st, "%[^\n] %[\n]", hdr)
        (nz,) = read_line(st, "%ld %[^\n] %[\n]", cnt)
        rows = []
        for _ in range(max(nz, 0)):
            im, ig, ia, value = read_line(st, "%ld %ld %ld %lf %[^\n] %[\n]", ent)
            if ig >= num_joints:  # 42init.c:1271 / 1297
                raise ReadFailure(f"{name}: 42 exits: Error in InitFlexModes: Joint {ig} out of range")
            if ia > 2:  # 1275 / 1301
                raise ReadFailure(f"{name}: 42 exits: Error in InitFlexModes ({kind}): Axis {ia} out of range")
            if im >= nf:  # 1279 / 1305
                raise ReadFailure(f"{name}: 42 exits: Error in InitFlexModes ({kind}): Flex Mode {im} out of range")
            put("joint" + kind, (im, ig, ia), value, ent)
            rows.append([im, ig, ia, value])
        joint[kind] = rows

    # Analysis node mode shapes (42init.c:1318-1362): FN->PSI[Ia][Im], FN->THETA[Ia][Im]
    read_line(st, "%[^\n] %[\n]", 1319)  # "Analysis Node Mode Shapes"
    shapes = {}
    for kind, hdr, cnt, ent in (("PSI", 1321, 1322, 1324), ("THETA", 1343, 1344, 1346)):
        arr = np.zeros((num_nodes, 3, nf))
        read_line(st, "%[^\n] %[\n]", hdr)
        (nz,) = read_line(st, "%ld %[^\n] %[\n]", cnt)
        for _ in range(max(nz, 0)):
            im, inode, ia, value = read_line(st, "%ld %ld %ld %lf %[^\n] %[\n]", ent)
            # 42init.c:1326/1349 (In > NumNodes-1); a negative index is out of the array too
            if inode > num_nodes - 1 or inode < 0:
                raise ReadFailure(f"{name}: 42 exits: Error in InitFlexModes ({kind}): Node {inode} out of range")
            if ia > 2 or ia < 0:  # 1331 / 1353
                raise ReadFailure(f"{name}: 42 exits: Error in InitFlexModes ({kind}): Axis {ia} out of range")
            if im >= nf or im < 0:  # 1335 / 1357
                raise ReadFailure(f"{name}: 42 exits: Error in InitFlexModes ({kind}): Flex Mode {im} out of range")
            put(kind, (inode, ia, im), value, ent)
            arr[inode, ia, im] = value
        shapes[kind] = arr

    # Mass, stiffness, damping (42init.c:1364-1399): "%ld %ld %lf" = row, column, value
    mats = {}
    for key, hdr, cnt, ent, label in (
        ("Mf", 1365, 1366, 1368, "Mass Matrix"),
        ("Kf", 1377, 1378, 1380, "Stiffness Matrix"),
        ("Cf", 1389, 1390, 1392, "Damping Matrix"),
    ):
        m = np.zeros((nf, nf))
        read_line(st, "%[^\n] %[\n]", hdr)
        (nz,) = read_line(st, "%ld %[^\n] %[\n]", cnt)
        for _ in range(max(nz, 0)):
            i, j, value = read_line(st, "%ld %ld %lf %[^\n] %[\n]", ent)
            if i >= nf or j >= nf or i < 0 or j < 0:  # 1370 / 1382 / 1394
                raise ReadFailure(f"{name}: 42 exits: Error in InitFlexModes: {label} index [{i}][{j}] out of range")
            put(key, (i, j), value, ent)
            m[i, j] = value
        mats[key] = m

    # Pf, 3 x Nf (42init.c:1411-1416): one line per mode, "%lf %lf %lf" = Pf[0..2][Im]
    read_line(st, "%[^\n] %[\n]", 1412)
    pf = np.zeros((3, nf))
    for f in range(nf):
        pf[:, f] = read_line(st, "%lf %lf %lf %[^\n] %[\n]", 1414)
    # Hf, 3 x Nf (42init.c:1417-1422)
    read_line(st, "%[^\n] %[\n]", 1418)
    hf = np.zeros((3, nf))
    for f in range(nf):
        hf[:, f] = read_line(st, "%lf %lf %lf %[^\n] %[\n]", 1420)

    # L, 3 x 3 x Nf (42init.c:1435-1447): "%ld %ld %ld %lf" = i, j, Im, value
    lmat = np.zeros((3, 3, nf))
    read_line(st, "%[^\n] %[\n]", 1438)
    (nz,) = read_line(st, "%ld %[^\n] %[\n]", 1439)
    for _ in range(max(nz, 0)):
        i, j, im, value = read_line(st, "%ld %ld %ld %lf %[^\n] %[\n]", 1441)
        if i >= 3 or j >= 3 or im >= nf or min(i, j, im) < 0:  # 1443
            raise ReadFailure(f"{name}: 42 exits: Error in InitFlexModes: L index [{i}][{j}][{im}] out of range")
        put("L", (i, j, im), value, 1441)
        lmat[i, j, im] = value

    # N, 3 x 3 x Nf x Nf (42init.c:1464-1481): "%ld %ld %ld %ld %lf" = i, j, Im, Jm, value
    nmat = np.zeros((3, 3, nf, nf))
    read_line(st, "%[^\n] %[\n]", 1472)
    (nz,) = read_line(st, "%ld %[^\n] %[\n]", 1473)
    for _ in range(max(nz, 0)):
        i, j, im, jm, value = read_line(st, "%ld %ld %ld %ld %lf %[^\n] %[\n]", 1475)
        if i >= 3 or j >= 3 or im >= nf or jm >= nf or min(i, j, im, jm) < 0:  # 1477
            raise ReadFailure(
                f"{name}: 42 exits: Error in InitFlexModes: N index [{i}][{j}][{im}][{jm}] out of range"
            )
        put("N", (i, j, im, jm), value, 1475)
        nmat[i, j, im, jm] = value

    # What 42 derives from L and N (42init.c:1449-1460 and 1482-1498), as 42 lays it out:
    # Rf[a][p][b], Qf[a][p][q], Sf[a][p][q][b].
    L = lmat
    rf = np.zeros((3, nf, 3))
    rf[0, :, 0] = -L[1, 1] - L[2, 2]
    rf[1, :, 1] = -L[2, 2] - L[0, 0]
    rf[2, :, 2] = -L[0, 0] - L[1, 1]
    rf[0, :, 1] = L[1, 0]
    rf[0, :, 2] = L[2, 0]
    rf[1, :, 0] = L[0, 1]
    rf[1, :, 2] = L[2, 1]
    rf[2, :, 0] = L[0, 2]
    rf[2, :, 1] = L[1, 2]
    N = nmat
    qf = np.stack([N[2, 1] - N[1, 2], N[0, 2] - N[2, 0], N[1, 0] - N[0, 1]])
    sf = np.zeros((3, nf, nf, 3))
    sf[0, :, :, 0] = -N[1, 1] - N[2, 2]
    sf[1, :, :, 1] = -N[2, 2] - N[0, 0]
    sf[2, :, :, 2] = -N[0, 0] - N[1, 1]
    sf[0, :, :, 1] = N[1, 0]
    sf[0, :, :, 2] = N[2, 0]
    sf[1, :, :, 0] = N[0, 1]
    sf[1, :, :, 2] = N[2, 1]
    sf[2, :, :, 0] = N[0, 2]
    sf[2, :, :, 1] = N[1, 2]

    mf = mats["Mf"]
    # 42init.c:1521-1530: MfIsDiagonal, exact zeros off the diagonal
    mf_is_diagonal = bool(np.all((mf - np.diag(np.diag(mf)))[~np.eye(nf, dtype=bool)] == 0.0))
    # 42init.c:1402-1403: wf = sqrt(Kf[i][i]/Mf[i][i]), must satisfy Pi/wf >= DTSIM
    with np.errstate(divide="ignore", invalid="ignore"):
        wf = np.sqrt(np.diag(mats["Kf"]) / np.diag(mf))
        max_dtsim = float(np.min(np.pi / wf)) if nf else math.inf

    return {
        "title": title,
        "nf": nf,
        "x": eta,
        "u": xi,
        "joint_psi": joint["PSI"],
        "joint_theta": joint["THETA"],
        "psi": shapes["PSI"],
        "theta": shapes["THETA"],
        "mf": mf,
        "kf": mats["Kf"],
        "cf": mats["Cf"],
        "pf": pf,
        "hf": hf,
        "l": lmat,
        "n": nmat,
        "rf": rf,
        "qf": qf,
        "sf": sf,
        "mf_is_diagonal": mf_is_diagonal,
        "omega": wf,
        "max_dtsim": max_dtsim,
        "unread": st.rest(),
    }


# ---------------------------------------------------------------------------------------
# The identities
# ---------------------------------------------------------------------------------------


def skew(a):
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def check(flex, nodes, args):
    fails = []
    notes = []
    rtol = args.rtol
    nf = flex["nf"]

    def bad(msg):
        fails.append(msg)

    arrays = {k: flex[k] for k in ("x", "u", "psi", "theta", "mf", "kf", "cf", "pf", "hf", "l", "n")}
    for k, a in arrays.items():
        if not np.all(np.isfinite(a)):
            bad(f"{k} has non-finite entries")
    if not np.all(np.isfinite(nodes["position"])):
        bad("node positions have non-finite entries")
    if nf == 0:
        bad("no flex modes (Nf = 0)")
        return fails, notes
    if fails:
        return fails, notes

    mf, kf, cf = flex["mf"], flex["kf"], flex["cf"]
    pf, hf, L, N = flex["pf"], flex["hf"], flex["l"], flex["n"]
    eye = np.eye(nf)

    # Mf = I and symmetric (mass-normalised modes)
    e = np.max(np.abs(mf - eye))
    notes.append(f"max |Mf - I| = {e:.3e}")
    if e > rtol:
        bad(f"Mf is not the identity: max |Mf - I| = {e:.3e} > {rtol:g}")

    # Kf: symmetric, diagonal, non-negative
    kscale = np.max(np.abs(np.diag(kf)))
    off = np.max(np.abs(kf - np.diag(np.diag(kf))))
    notes.append(f"Kf: max off-diagonal / max diagonal = {off / kscale if kscale else off:.3e}")
    if off > rtol * kscale:
        bad(f"Kf is not diagonal: max off-diagonal {off:.3e} > {rtol:g} * {kscale:.3e}")
    if np.any(np.diag(kf) < 0):
        bad(f"Kf has negative diagonal entries (omega^2 < 0): {np.diag(kf)[np.diag(kf) < 0]}")
    if np.max(np.abs(kf - kf.T)) > rtol * kscale:
        bad("Kf is not symmetric")

    # Cf: symmetric, positive semi-definite
    cscale = max(np.max(np.abs(cf)), 1e-300)
    if np.max(np.abs(cf - cf.T)) > rtol * cscale:
        bad("Cf is not symmetric")
    ceig = np.linalg.eigvalsh(0.5 * (cf + cf.T))
    if ceig[0] < -rtol * cscale:
        bad(f"Cf is not positive semi-definite: smallest eigenvalue {ceig[0]:.3e}")
    with np.errstate(divide="ignore", invalid="ignore"):
        zeta = np.diag(cf) / (2.0 * np.sqrt(np.diag(kf) * np.diag(mf)))
    flex["zeta"] = zeta

    # N: Gram symmetry N_abpq = N_baqp
    nscale = np.max(np.abs(N))
    e = np.max(np.abs(N - N.transpose(1, 0, 3, 2)))
    notes.append(f"max |N_abpq - N_baqp| = {e:.3e} (max |N| = {nscale:.3e})")
    if e > rtol * max(nscale, 1.0):
        bad(f"N is not symmetric under (a,p) <-> (b,q): {e:.3e}")
    # trace over the spatial index = modal mass
    tr = np.einsum("aapq->pq", N)
    e = np.max(np.abs(tr - mf))
    notes.append(f"max |sum_a N_aapq - Mf_pq| = {e:.3e}")
    if e > rtol * max(np.max(np.abs(mf)), 1.0):
        bad(f"sum_a N_aapq differs from Mf_pq by {e:.3e}")
    # N as the Gram matrix of {Psi_ap}: positive semi-definite
    G = N.transpose(0, 2, 1, 3).reshape(3 * nf, 3 * nf)
    geig = np.linalg.eigvalsh(0.5 * (G + G.T))
    notes.append(f"Gram matrix of the shapes (N): eigenvalues in [{geig[0]:.3e}, {geig[-1]:.3e}]")
    if geig[0] < -rtol * geig[-1]:
        bad(f"N is not positive semi-definite: smallest eigenvalue {geig[0]:.3e} (largest {geig[-1]:.3e})")

    # Hf = antisymmetric part of L: (int r x Psi)_x = int (r_y Psi_z - r_z Psi_y) = L_zy - L_yz
    hl = np.stack([L[2, 1] - L[1, 2], L[0, 2] - L[2, 0], L[1, 0] - L[0, 1]])
    hscale = max(np.max(np.abs(hf)), np.max(np.abs(L)), 1e-300)
    e = np.max(np.abs(hl - hf))
    notes.append(f"max |Hf - antisym(L)| = {e:.3e} (scale {hscale:.3e})")
    if e > rtol * hscale:
        bad(f"Hf differs from the antisymmetric part of L (int r x Psi dm) by {e:.3e} (scale {hscale:.3e})")

    # The modal frequencies 42 checks against DTSIM
    if args.dtsim is not None and flex["max_dtsim"] < args.dtsim:
        bad(f"42 exits: a flex mode is too high to be sampled at DTSIM = {args.dtsim} (pi/omega = {flex['max_dtsim']:.3e})")

    # Effective-mass bounds, with the body's mass properties from the command line
    if args.mass is not None:
        m = args.mass
        c = np.array(args.cm)
        s = m * c
        jo = np.array(args.inertia_ref).reshape(3, 3)
        if np.max(np.abs(jo - jo.T)) > 1e-12 * np.max(np.abs(jo)):
            bad("--inertia-ref is not symmetric")
        mo = np.block([[m * np.eye(3), -skew(s)], [skew(s), jo]])
        q = np.vstack([pf, hf])
        minv = np.linalg.pinv(mf)
        eff = q @ minv @ q.T
        for label, a, b in (
            ("sum_p Pf_p Pf_p^T <= m I", m * np.eye(3), eff[:3, :3]),
            ("sum_p Hf_p Hf_p^T <= J_O", jo, eff[3:, 3:]),
            ("[Pf;Hf] Mf^-1 [Pf;Hf]^T <= M_O (6 x 6)", mo, eff),
        ):
            # generalized eigenvalues of b against a: the fraction of the rigid mass the kept
            # modes carry in the worst direction; <= 1 is the bound
            w = np.linalg.eigvalsh(a)
            ah = (np.linalg.cholesky(a)) if w[0] > 0 else None
            if ah is None:
                bad(f"{label}: the given rigid mass is not positive definite")
                continue
            ai = np.linalg.inv(ah)
            frac = np.linalg.eigvalsh(ai @ b @ ai.T)
            notes.append(f"{label}: largest fraction {frac[-1]:.6f}")
            if frac[-1] > 1.0 + rtol:
                bad(f"effective-mass bound violated: {label}: the kept modes carry {frac[-1]:.9f} of it")
        # Gram of {1, r_x, r_y, r_z, Psi_ap}: [[m, s^T, P^T], [s, E, Lr^T], [P, Lr, G]]
        E = 0.5 * np.trace(jo) * np.eye(3) - jo  # int r r^T dm
        P = pf.reshape(3 * nf)  # index (a, p) -> a*nf + p
        Lr = L.transpose(0, 2, 1).reshape(3 * nf, 3)  # [(a,p), b] = int Psi_ap r_b dm
        full = np.block(
            [
                [np.array([[m]]), s[None, :], P[None, :]],
                [s[:, None], E, Lr.T],
                [P[:, None], Lr, G],
            ]
        )
        # block scaling (not row by row: a shape component that is zero for a mode has a
        # zero diagonal, and dividing rounding noise by it would manufacture eigenvalues)
        escale = max(np.linalg.eigvalsh(E)[-1], 1e-300)
        d = np.concatenate([[math.sqrt(m)], np.full(3, math.sqrt(escale)), np.full(3 * nf, math.sqrt(max(geig[-1], 1e-300)))])
        norm = full / np.outer(d, d)
        feig = np.linalg.eigvalsh(0.5 * (norm + norm.T))
        if np.linalg.eigvalsh(E)[0] < 0:
            bad("--inertia-ref is not the inertia of a mass distribution (tr(J)/2 I - J not positive semi-definite)")
        notes.append(f"Gram of {{1, r, Psi}} (normalised): smallest eigenvalue {feig[0]:.3e}")
        if feig[0] < -rtol * feig[-1]:
            bad(
                "the mass moments and the modal integrals are not the Gram matrix of one mass "
                f"distribution (not positive semi-definite): smallest normalised eigenvalue {feig[0]:.3e}"
            )
        flex["effective_mass_6x6"] = eff
    return fails, notes


def to_json(flex, nodes, args):
    def arr(a):
        return np.asarray(a, dtype=float).tolist()

    out = {
        "reader": "scripts/check_flex42_numpy.py, replaying NASA 42 (11e3cc39) 42init.c InitFlexModes and InitNodes",
        "flex_file": os.path.abspath(args.flex),
        "nodes_file": os.path.abspath(args.nodes),
        "title": flex["title"],
        "nf": flex["nf"],
        "x": arr(flex["x"]),
        "u": arr(flex["u"]),
        "joint_psi": flex["joint_psi"],
        "joint_theta": flex["joint_theta"],
        "num_nodes": nodes["num_nodes"],
        "node_position": arr(nodes["position"]),
        "node_comment": nodes["comment"],
        "psi": arr(flex["psi"]),  # [node][axis][mode]
        "theta": arr(flex["theta"]),  # [node][axis][mode]
        "mf": arr(flex["mf"]),
        "kf": arr(flex["kf"]),
        "cf": arr(flex["cf"]),
        "pf": arr(flex["pf"]),  # [axis][mode]
        "hf": arr(flex["hf"]),  # [axis][mode]
        "l": arr(flex["l"]),  # [a][b][mode]
        "n": arr(flex["n"]),  # [a][b][mode][mode]
        "rf": arr(flex["rf"]),  # [a][mode][b]
        "qf": arr(flex["qf"]),  # [a][mode][mode]
        "sf": arr(flex["sf"]),  # [a][mode][mode][b]
        "mf_is_diagonal": flex["mf_is_diagonal"],
        "omega": [float(w) for w in flex["omega"]],
        "max_dtsim": flex["max_dtsim"],
        "flex_unread": flex["unread"],
        "nodes_unread": nodes["unread"],
    }
    if "zeta" in flex:
        out["zeta"] = arr(flex["zeta"])
    if "effective_mass_6x6" in flex:
        out["effective_mass_6x6"] = arr(flex["effective_mass_6x6"])
    return out


def _floats(n):
    # comma-separated, so that negative numbers are not taken for options
    def parse(text):
        v = [float(x) for x in text.split(",")]
        if len(v) != n:
            raise argparse.ArgumentTypeError(f"expected {n} comma-separated numbers, got {len(v)}")
        return v

    return parse


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("flex")
    ap.add_argument("nodes")
    ap.add_argument("--json", required=True, help="where to write the parsed arrays")
    ap.add_argument("--rtol", type=float, default=1e-9)
    ap.add_argument("--joints", type=int, default=0, help="42's S->Ng (0: a single body)")
    ap.add_argument("--dtsim", type=float, default=None)
    ap.add_argument("--mass", type=float, default=None, help="body mass, kg")
    ap.add_argument("--cm", type=_floats(3), default=None, help="centre of mass, m: X,Y,Z")
    ap.add_argument(
        "--inertia-ref", type=_floats(9), default=None,
        help="inertia tensor about the reference point, kg m^2, row-major: J11,J12,...,J33",
    )
    args = ap.parse_args()
    given = [args.mass is not None, args.cm is not None, args.inertia_ref is not None]
    if any(given) and not all(given):
        ap.error("--mass, --cm and --inertia-ref go together")

    fails = []
    for path in (args.flex, args.nodes):
        # 42 reads the names with %s into char[40] (42init.c:2089-2090)
        if len(os.path.basename(path).encode()) > FILE_NAME_BYTES - 1:
            fails.append(f"{os.path.basename(path)}: longer than 42's {FILE_NAME_BYTES}-byte file name")
    try:
        with open(args.nodes, "rb") as fh:
            ntext = fh.read().decode("latin-1")
        with open(args.flex, "rb") as fh:
            ftext = fh.read().decode("latin-1")
        # InitNodes runs first (42init.c:2096, per body), InitFlexModes later (2859)
        nodes = read_nodes(ntext, os.path.basename(args.nodes))
        flex = read_flex(ftext, os.path.basename(args.flex), nodes["num_nodes"], args.joints)
    except ReadFailure as e:
        print(f"FAIL (42 reads the file wrong): {e}")
        return 1
    more, notes = check(flex, nodes, args)
    fails += more
    with open(args.json, "w") as fh:
        json.dump(to_json(flex, nodes, args), fh, indent=1, allow_nan=True)
    print(f"read {args.flex}: Nf = {flex['nf']}, {nodes['num_nodes']} nodes; 42's largest DTSIM {flex['max_dtsim']:.4e} s")
    for n in notes:
        print("  " + n)
    for f in fails:
        print("FAIL: " + f)
    if fails:
        return 1
    print("every check passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
