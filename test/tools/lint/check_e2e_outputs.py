#!/usr/bin/env python3
"""Review rule for the end-to-end tests (issue 27): a test that makes the tool write a file must
look at that file. For each TEST in test/e2e/*.cpp, every output option given to the tool
(-o, --output, --stats, --motions-out, --out, --out-dir, --plane-out) is followed to the
expression that names the file; that expression's variable (or literal file name) must appear
again, after the command, on a line that reads or checks it: an EXPECT_/ASSERT_, a call that reads
a file (read_*, load, imread, exists, file_size, ifstream, ...) or any other call that takes it, or
a later command or C API call that takes it as input. A heuristic: it finds the outputs a test
never mentions again, the commonest way an end-to-end test stops testing what it names.

A command whose output is deliberately ignored says so with `// output unchecked: <why>` on its
line or the line before. Exit 1 listing each test and output otherwise.

  test/tools/lint/check_e2e_outputs.py [FILE...]   (default: test/e2e/*.cpp)
"""
import glob
import os
import re
import sys

OUTPUT_FLAGS = r"(?:-o|--output|--stats|--motions-out|--out|--out-dir|--plane-out)"
# "... -o " + expr   (the expression up to the next + or the end of the call)
FLAG_THEN_EXPR = re.compile(r'"[^"]*?(?<![\w-])' + OUTPUT_FLAGS + r'\s"\s*\+\s*([^;]*?)(?=\s*\+\s*"|\s*\)|\s*;|\s*\+\s*\w)')
# ... " -o out.txt" inside one literal
FLAG_IN_LITERAL = re.compile(r'(?<![\w-])' + OUTPUT_FLAGS + r'\s+([\w./-]+)')
READS = re.compile(r'EXPECT_|ASSERT_|read_|load|imread|exists|file_size|ifstream|fopen|open\(|compare|parse|lines\(|'
                   r'check_|same_|equal|matches|diff|expect_|\w\(')
TEST_START = re.compile(r'^(TEST|TEST_F|TEST_P)\((\w+),\s*(\w+)\)', re.M)


def names_in(expr):
    """The identifiers and quoted file names an expression is made of (dir / "x.txt" -> dir, x.txt)."""
    literals = re.findall(r'"([^"]+)"', expr)
    idents = [w for w in re.findall(r'[A-Za-z_]\w*', re.sub(r'"[^"]*"', ' ', expr))
              if w not in ("string", "c_str", "std", "fs", "path", "scratch", "dir", "tmp", "d", "data")]
    return idents, literals


def check_body(name, body):
    problems = []
    lines = body.split("\n")
    for i, line in enumerate(lines):
        if "run_cli" not in line and "run_command" not in line and "planarvo " not in line:
            # the command may span lines: look at the statement the line belongs to
            pass
        found = []
        for m in FLAG_THEN_EXPR.finditer(line):
            found.append(m.group(1))
        for lit in re.findall(r'"([^"]*)"', line):
            for m in FLAG_IN_LITERAL.finditer(lit):
                found.append('"' + m.group(1) + '"')
        if not found:
            continue
        # Marked on its line, or above it in the comment or the rows of the same table of commands.
        marked = "output unchecked" in line
        for j in range(i - 1, max(-1, i - 16), -1):
            above = lines[j].strip()
            if not (above.startswith("//") or above.startswith('{"')):
                break
            marked = marked or "output unchecked" in above
        if marked:
            continue
        for expr in found:
            idents, literals = names_in(expr)
            keys = idents + [os.path.basename(l.strip("/")) for l in literals if l.strip("/")]
            if not keys:
                continue
            # Read or checked, or the input of a later command (which is then checked in turn).
            later = "\n".join(l for l in lines[i + 1:] if READS.search(l) or "run_" in l or "planarvo_" in l)
            if not any(re.search(r'(?<![\w.])' + re.escape(k) + r'(?!\w)', later) for k in keys):
                problems.append("%s: line %d: the output %s is never read or checked" % (name, i + 1, expr.strip()))
    return problems


def main(argv):
    files = argv[1:] or sorted(glob.glob(os.path.join(os.path.dirname(__file__), "../../e2e/*.cpp")))
    problems = []
    for path in files:
        text = open(path, encoding="utf-8").read()
        starts = [(m.start(), "%s.%s" % (m.group(2), m.group(3))) for m in TEST_START.finditer(text)]
        for k, (at, name) in enumerate(starts):
            end = starts[k + 1][0] if k + 1 < len(starts) else len(text)
            problems += ["%s: %s" % (os.path.relpath(path), p) for p in check_body(name, text[at:end])]
    for p in problems:
        print(p)
    if problems:
        print("check_e2e_outputs: %d output(s) written and never looked at; check them, or mark the line "
              "`// output unchecked: <why>`" % len(problems))
        return 1
    print("check_e2e_outputs: %d files, every output a test writes is read or checked" % len(files))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
