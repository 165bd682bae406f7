#!/usr/bin/env python3
"""The C API's copies, generated from its one list, the public headers (run by CMakeLists.txt).

Every `PLANARVO_API <return> <name>(<parameters>);` of include/planarvo/*.h is a function of the C
API. From them this writes:
  - the forwarders of libplanarvo.so: every function that the base library's sources do not
    define is looked up in the vision module on its first call (src/capi/README.md, "Two
    binaries");
  - planarvo_api_signatures(): each function's return and parameter types as text, which the
    Python package reads to declare its ctypes prototypes (python/planarvo/_native.py).
It fails (and so does the build) when a declared function is defined in no source under
src/capi/base or src/capi/vision, or one is defined twice, or a source defines a PLANARVO_API
function that no header declares.

usage: generate_capi.py OUT_FORWARD.cpp OUT_SIGNATURES.cpp --headers H... --base B... --module M...
"""
import argparse
import os
import re
import sys

DECL = re.compile(r"PLANARVO_API\s+([^;{]*?)\b(planarvo_\w+)\s*\(([^;{]*?)\)\s*;", re.S)
DEFN = re.compile(r"PLANARVO_API\s+[^;{()]*?\b(planarvo_\w+)\s*\(([^;{]*?)\)\s*\{", re.S)


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.sub(r"//[^\n]*", " ", text)


def squeeze(s):
    return " ".join(s.replace("*", " * ").replace("[", " [ ").replace("]", " ] ").split())


def split_params(params):
    params = params.strip()
    if params in ("", "void"):
        return []
    out, depth, cur = [], 0, ""
    for ch in params:
        if ch == "," and depth == 0:
            out.append(cur)
            cur = ""
            continue
        depth += ch == "("
        depth -= ch == ")"
        cur += ch
    out.append(cur)
    return [p.strip() for p in out]


def param_type_and_name(p):
    """'const double* covariance' -> ('const double*', 'covariance'); 'double matrix[16]' ->
    ('double[16]', 'matrix')."""
    m = re.match(r"^(.*?)(\w+)\s*(\[\s*\d*\s*\])?$", p.strip(), re.S)
    if not m:
        raise SystemExit("generate_capi: cannot read the parameter '%s'" % p)
    base, name, array = m.group(1), m.group(2), m.group(3) or ""
    type_ = squeeze(base).replace(" *", "*").replace("* *", "**")
    if array:
        type_ += squeeze(array).replace(" ", "")
    return type_.strip(), name


def read_declarations(headers):
    funcs = []
    for h in headers:
        text = strip_comments(open(h, encoding="utf-8").read())
        text = text.replace("#define PLANARVO_API", "")
        for m in DECL.finditer(text):
            ret = squeeze(m.group(1)).replace(" *", "*")
            params = [param_type_and_name(p) for p in split_params(m.group(3))]
            funcs.append((m.group(2), ret, params, m.group(0)))
    names = [f[0] for f in funcs]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise SystemExit("generate_capi: declared twice: %s" % ", ".join(sorted(dup)))
    return funcs


def read_definitions(sources):
    defined = {}
    for s in sources:
        text = strip_comments(open(s, encoding="utf-8").read())
        for m in DEFN.finditer(text):
            defined.setdefault(m.group(1), []).append(s)
    return defined


def forwarder(name, ret, params, decl):
    signature = decl[len("PLANARVO_API"):].strip().rstrip(";").strip()
    signature = " ".join(signature.split())
    args = ", ".join(p[1] for p in params)
    if ret == "void":
        body = "  if (fn) fn(%s);" % args
    elif ret == "planarvo_status":
        body = "  return fn ? fn(%s) : PLANARVO_ERROR_INTERNAL;" % args
    elif ret.endswith("*"):
        body = "  return fn ? fn(%s) : nullptr;" % args
    else:
        body = "  return fn ? fn(%s) : %s{};" % (args, ret)
    return "PLANARVO_API %s {\n  PLANARVO_FORWARD(%s);\n%s\n}\n" % (signature, name, body)


def write_if_changed(path, text):
    if os.path.exists(path) and open(path, encoding="utf-8").read() == text:
        return
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("forward")
    ap.add_argument("signatures")
    ap.add_argument("--headers", nargs="+", required=True)
    ap.add_argument("--base", nargs="+", required=True)
    ap.add_argument("--module", nargs="+", required=True)
    a = ap.parse_args()
    funcs = read_declarations(a.headers)
    base = read_definitions(a.base)
    base.setdefault("planarvo_api_signatures", ["the generated signatures"])
    module = read_definitions(a.module)
    problems = []
    declared = {f[0] for f in funcs}
    for name, _, _, _ in funcs:
        where = base.get(name, []) + module.get(name, [])
        if not where:
            problems.append("%s is declared but defined in no source under src/capi/base or src/capi/vision" % name)
        elif len(where) > 1:
            problems.append("%s is defined more than once: %s" % (name, ", ".join(where)))
    for name, where in list(base.items()) + list(module.items()):
        if name not in declared and name != "planarvo_vision_attach":
            problems.append("%s (%s) is defined but no public header declares it" % (name, where[0]))
    if problems:
        sys.exit("generate_capi: " + "\n  ".join(problems))

    out = ["// Generated by cmake/generate_capi.py from include/planarvo/*.h. Do not edit.",
           "// The C API functions that live in the vision module, forwarded to it: each looks its",
           "// function up on the first call (loading the module then) and calls it.",
           '#include "capi/host/vision_module.h"', '#include "planarvo/planarvo.h"', "",
           "namespace {", "", "template <class F>", "F lookup(const char* name) {",
           "  return reinterpret_cast<F>(planarvo::capi::host::vision_symbol(name));", "}", "",
           "}  // namespace", "",
           "// Each forwarder keeps its function pointer in a static: the module, once loaded, stays.",
           "#define PLANARVO_FORWARD(name) static const auto fn = lookup<decltype(&name)>(#name)", "",
           'extern "C" {', ""]
    forwarded = 0
    for name, ret, params, decl in funcs:
        if name in base:
            continue
        out.append(forwarder(name, ret, params, decl))
        forwarded += 1
    out.append('}  // extern "C"')
    write_if_changed(a.forward, "\n".join(out) + "\n")

    lines = ["%s|%s|%s" % (name, ret, ",".join(p[0] for p in params)) for name, ret, params, _ in funcs]
    sig = ["// Generated by cmake/generate_capi.py from include/planarvo/*.h. Do not edit.",
           '#include "planarvo/planarvo.h"', "", 'extern "C" {',
           "PLANARVO_API const char* planarvo_api_signatures(void) {",
           "  return"] + ['      "%s\\n"' % l for l in lines] + ["      ;", "}", '}  // extern "C"']
    write_if_changed(a.signatures, "\n".join(sig) + "\n")


if __name__ == "__main__":
    main()
