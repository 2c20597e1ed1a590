#!/usr/bin/python3
"""How much a string's step decides, and how big the scheme's classes are.

Parses the scheme's sources with libclang (Debian: python3-clang) and builds the call graph of
the library's own functions: an edge for every call, every reference to a function (a function
pointer, such as the plan's step kernel), and from a virtual method to each override. From the
roots (the three phases of a string's step and Assembly::step, or --root) it walks every
function reachable and counts its decision points: `if`, `?:`, `&&`, `||` and `case` (a
lambda's are its enclosing function's). It then reports

- the decision points a step can reach (the sum over reachable functions), the largest;
- the decisions taken in more than one function: a condition's atoms (split at &&, ||, !) that
  read the same flag, normalised so that `plan_->options().fused_step` and `fused_step`, or
  `record.loaded` and a parameter `loaded`, are one (a member chain keeps its last name, two
  where the last is generic, such as empty() or size()); atoms without a member, a call or a
  flag of type bool (loop counters, comparisons of locals) are left out;
- every class defined in the scheme's folders: its methods (declared in the class, = default
  and = delete left out) and its lines (the class's own, plus its methods defined outside it),
  and the longest function there.

  scripts/step_decisions.py                  # this checkout
  scripts/step_decisions.py --repo /work/base --json before.json
Templates are read as written: a call on a template parameter (law.solve(...)) resolves to the
methods of that name of the classes --instantiate names for it (the laws the plan offers).
"""
import argparse
import collections
import json
import os
import re
import sys

import clang.cindex as ci

CK = ci.CursorKind
FUNCTION_KINDS = {CK.FUNCTION_DECL, CK.CXX_METHOD, CK.CONSTRUCTOR, CK.DESTRUCTOR, CK.FUNCTION_TEMPLATE,
                  CK.CONVERSION_FUNCTION}
CLASS_KINDS = {CK.CLASS_DECL, CK.STRUCT_DECL, CK.CLASS_TEMPLATE}
DEFAULT_ROOTS = ["fretbuzz::VibratingString::begin_step", "fretbuzz::VibratingString::solve_contacts",
                 "fretbuzz::VibratingString::end_step", "fretbuzz::Assembly::step"]
# Names too general to identify a flag alone: the chain keeps the owner's name with them.
# The step programs a plan chooses among (StepPrograms' entry points): with --programs, the
# decisions a step of each can reach (the others' entry points not entered).
PROGRAMS = ["joint_law", "played", "free", "points_and_grid", "points", "grid"]
GENERIC = {"empty", "size", "data", "begin", "end", "front", "back", "count", "first", "second", "on", "off",
           "value", "has_value", "get"}


def qualified(c):
    parts = []
    while c is not None and c.kind != CK.TRANSLATION_UNIT:
        if c.spelling:
            parts.append(c.spelling)
        c = c.semantic_parent
    return "::".join(reversed(parts))


class Function:
    def __init__(self, cursor, repo):
        self.usr = cursor.get_usr()
        self.name = qualified(cursor)
        self.file = os.path.relpath(cursor.location.file.name, repo)
        self.first = cursor.extent.start.line
        self.last = cursor.extent.end.line
        self.decisions = 0
        self.atoms = set()  # normalised flag atoms of its if/?: conditions
        self.callees = set()  # USRs
        self.unresolved = set()  # member names called on a template parameter
        self.indirect = set()  # argument counts of its calls through a function pointer

    @property
    def lines(self):
        return self.last - self.first + 1


def tokens_of(cursor):
    return [t.spelling for t in cursor.get_tokens()]


def binary_operator(cursor):
    children = list(cursor.get_children())
    if len(children) != 2:
        return None
    lhs_end, rhs_start = children[0].extent.end.offset, children[1].extent.start.offset
    for t in cursor.get_tokens():
        if lhs_end <= t.extent.start.offset < rhs_start:
            return t.spelling
    return None


def split_atoms(tokens):
    """Top-level operands of && and || (parentheses and ! peeled)."""
    atoms, depth, current = [], 0, []
    for t in tokens:
        if t in "([{":
            depth += 1
        elif t in ")]}":
            depth -= 1
        if depth == 0 and t in ("&&", "||"):
            atoms.append(current)
            current = []
        else:
            current.append(t)
    atoms.append(current)
    out = []
    for a in atoms:
        while a and a[0] == "!":
            a = a[1:]
        if len(a) >= 2 and a[0] == "(" and a[-1] == ")" and balanced(a[1:-1]):
            out.extend(split_atoms(a[1:-1]))
        elif a:
            out.append(a)
    return out


def balanced(tokens):
    depth = 0
    for t in tokens:
        depth += t in "([{"
        depth -= t in ")]}"
        if depth < 0:
            return False
    return depth == 0


def normalise_chain(chain):
    """['plan_', '->', 'options', '(', ')', '.', 'fused_step'] -> 'options().fused_step' or 'fused_step'."""
    links, current, depth = [], [], 0
    for t in chain:
        if depth == 0 and t in (".", "->"):
            links.append(current)
            current = []
            continue
        depth += t in "([{"
        depth -= t in ")]}"
        current.append(t)
    links.append(current)
    links = [l for l in links if l and l != ["this"]]
    if not links:
        return ""

    def text(link):
        return "".join(re.sub(r"_$", "", t) if re.match(r"^[A-Za-z_]\w*$", t) else t for t in link)

    last = text(links[-1])
    head = re.match(r"^[A-Za-z_]\w*", last)
    if head and head.group(0) in GENERIC and len(links) > 1:
        return text(links[-2]) + "." + last
    return last


def normalise_atom(tokens):
    """Each member chain to its last name (see normalise_chain), the rest kept."""
    out, chain = [], []
    i = 0
    while i < len(tokens):
        t = tokens[i]
        if re.match(r"^[A-Za-z_]\w*$", t) or (t in (".", "->") and chain) or (t in "([" and chain):
            if t in "([":  # a call's or subscript's arguments stay in the chain
                close = ")" if t == "(" else "]"
                depth, j = 0, i
                while j < len(tokens):
                    depth += tokens[j] in "(["
                    depth -= tokens[j] in ")]"
                    if depth == 0:
                        break
                    j += 1
                inner = normalise_atom(tokens[i + 1:j]).replace(" ", "")
                chain.extend([t, inner, close] if inner else [t, close])
                i = j + 1
                continue
            chain.append(t)
        else:
            if chain:
                out.append(normalise_chain(chain))
                chain = []
            out.append(t)
        i += 1
    if chain:
        out.append(normalise_chain(chain))
    return " ".join(out)


def is_flag_atom(tokens, bool_names):
    """A condition's atom that reads a flag: a member, a call or a bool variable, perhaps compared.

    Left out: per-point values (subscripts), arithmetic, the standard library's tests
    (std::isfinite) and atoms on a plain local (a loop counter, an index)."""
    if "[" in tokens or "::" in tokens or any(t in ("+", "-", "*", "/", "%") for t in tokens):
        return False
    for k, t in enumerate(tokens):
        if not re.match(r"^[A-Za-z_]\w*$", t) or t in ("true", "false", "nullptr", "this"):
            continue
        before = tokens[k - 1] if k > 0 else ""
        after = tokens[k + 1] if k + 1 < len(tokens) else ""
        bare = before not in (".", "->") and after not in ("(", ".", "->")
        if bare and t not in bool_names and not t.endswith("_"):
            return False
    return True


class Graph:
    def __init__(self, repo, instantiate):
        self.repo = os.path.realpath(repo)
        self.functions = {}
        self.overrides = collections.defaultdict(set)
        self.instantiate = instantiate  # template parameter name -> class names
        self.methods_by_name = collections.defaultdict(set)  # (class, method) -> USRs
        self.classes = {}
        self.address_taken = {}  # USR -> parameter count: functions used as values (pointers)
        self.by_class = collections.defaultdict(list)  # class USR -> (name, USR, virtual)
        self.bases = collections.defaultdict(set)  # class USR -> its direct bases' USRs

    def ours(self, cursor):
        f = cursor.location.file
        return f is not None and os.path.realpath(f.name).startswith(self.repo + os.sep)

    def parse(self, files, args):
        index = ci.Index.create()
        for path in files:
            tu = index.parse(path, args=args, options=0)
            errors = [d for d in tu.diagnostics if d.severity >= ci.Diagnostic.Error]
            for d in errors[:5]:
                print(f"warning: {path}: {d.spelling}", file=sys.stderr)
            self.walk_declarations(tu.cursor)

    def walk_declarations(self, cursor):
        for c in cursor.get_children():
            if not self.ours(c) and c.kind != CK.NAMESPACE:
                continue
            if c.kind in FUNCTION_KINDS:
                self.method_seen(c)
                if c.is_definition():
                    self.define(c)
            if c.kind in CLASS_KINDS and c.is_definition():
                self.class_seen(c)
            if c.kind == CK.VAR_DECL:
                self.scan_values(c)
            if c.kind in (CK.NAMESPACE, CK.CLASS_DECL, CK.STRUCT_DECL, CK.CLASS_TEMPLATE, CK.LINKAGE_SPEC):
                self.walk_declarations(c)

    def method_seen(self, c):
        parent = c.semantic_parent
        if parent is not None and parent.kind in CLASS_KINDS:
            self.methods_by_name[(parent.spelling, c.spelling)].add(c.canonical.get_usr())
            # (libclang 14's bindings have no overridden cursors: a method overrides the virtual
            # method of its name in a base class, matched once every class is seen.)
            self.by_class[parent.get_usr()].append((c.spelling, c.canonical.get_usr(), c.is_virtual_method()))

    def class_seen(self, c):
        usr = c.get_usr()
        if usr in self.classes:
            return
        for b in c.get_children():
            if b.kind == CK.CXX_BASE_SPECIFIER and b.referenced is not None:
                self.bases[usr].add(b.referenced.get_usr())
        methods = 0
        for m in c.get_children():
            if m.kind in (CK.CXX_METHOD, CK.CONSTRUCTOR, CK.DESTRUCTOR, CK.FUNCTION_TEMPLATE, CK.CONVERSION_FUNCTION):
                text = " ".join(tokens_of(m))
                if re.search(r"=\s*(default|delete)\b", text):
                    continue
                methods += 1
        self.classes[usr] = {
            "name": qualified(c),
            "file": os.path.relpath(c.location.file.name, self.repo),
            "methods": methods,
            "lines": c.extent.end.line - c.extent.start.line + 1,
        }

    def define(self, cursor):
        usr = cursor.canonical.get_usr()
        if usr in self.functions:
            return
        f = Function(cursor, self.repo)
        f.usr = usr
        parent = cursor.semantic_parent
        f.class_usr = parent.get_usr() if parent is not None and parent.kind in CLASS_KINDS else None
        f.out_of_line = cursor.lexical_parent is not None and cursor.lexical_parent.kind not in CLASS_KINDS
        self.functions[usr] = f
        bool_names = {p.spelling for p in cursor.get_arguments() if p.type.spelling == "bool"}
        self.walk_body(cursor, f, bool_names)
        self.scan_values(cursor)

    def walk_body(self, cursor, f, bool_names):
        for c in cursor.get_children():
            k = c.kind
            if k == CK.IF_STMT:
                f.decisions += 1
                self.condition_atoms(f, if_condition(c), bool_names)
            elif k == CK.CONDITIONAL_OPERATOR:
                f.decisions += 1
                children = list(c.get_children())
                if children:
                    self.condition_atoms(f, tokens_of(children[0]), bool_names)
            elif k == CK.BINARY_OPERATOR and binary_operator(c) in ("&&", "||"):
                f.decisions += 1
            elif k == CK.CASE_STMT:
                f.decisions += 1
            elif k == CK.VAR_DECL and c.type.spelling in ("bool", "const bool"):
                bool_names.add(c.spelling)
            elif k == CK.FIELD_DECL:
                pass
            if k in (CK.CALL_EXPR, CK.DECL_REF_EXPR, CK.MEMBER_REF_EXPR):
                ref = c.referenced
                if ref is not None and ref.kind in FUNCTION_KINDS:
                    f.callees.add(ref.canonical.get_usr())
                elif k == CK.CALL_EXPR and (ref is None or ref.kind in (CK.VAR_DECL, CK.PARM_DECL, CK.FIELD_DECL)) and \
                        through_pointer(c):
                    # A call through a function pointer (the plan's step kernel, the program's
                    # solve): it may reach any function used as a value with as many parameters.
                    f.indirect.add(len(list(c.get_arguments())))
                elif ref is None and k == CK.CALL_EXPR and c.spelling:
                    f.unresolved.add(c.spelling)
                elif ref is None and k == CK.MEMBER_REF_EXPR and c.spelling:
                    f.unresolved.add(c.spelling)
            if k == CK.OVERLOADED_DECL_REF:
                for i in range(ci.conf.lib.clang_getNumOverloadedDecls(c)):
                    d = ci.conf.lib.clang_getOverloadedDecl(c, i)
                    if d is not None and d.kind in FUNCTION_KINDS:
                        f.callees.add(d.canonical.get_usr())
            self.walk_body(c, f, bool_names)

    def scan_values(self, cursor):
        """Functions named outside a call's callee position: taken as values (pointers)."""
        stack = [(cursor, False)]
        while stack:
            c, callee = stack.pop()
            if c.kind == CK.DECL_REF_EXPR and not callee:
                ref = c.referenced
                if ref is not None and ref.kind in (CK.FUNCTION_DECL, CK.CXX_METHOD) and self.ours(ref):
                    self.address_taken[ref.canonical.get_usr()] = len(list(ref.get_arguments()))
            for i, child in enumerate(c.get_children()):
                position = (c.kind == CK.CALL_EXPR and i == 0) or (callee and c.kind == CK.UNEXPOSED_EXPR)
                stack.append((child, position))

    def condition_atoms(self, f, tokens, bool_names):
        for atom in split_atoms(tokens):
            if is_flag_atom(atom, bool_names):
                key = normalise_atom(atom)
                if key:
                    f.atoms.add(key)

    def link_overrides(self):
        def ancestors(usr):
            seen, stack = set(), [usr]
            while stack:
                for b in self.bases.get(stack.pop(), ()):
                    if b not in seen:
                        seen.add(b)
                        stack.append(b)
            return seen

        for cls, methods in self.by_class.items():
            for base in ancestors(cls):
                virtual = {name: usr for name, usr, v in self.by_class.get(base, ()) if v}
                for name, usr, _ in methods:
                    if name in virtual:
                        self.overrides[virtual[name]].add(usr)

    def resolve(self, name):
        return [u for u in self.functions.values() if u.name == name]

    def callees(self, f):
        out = set()
        for usr in f.callees:
            out.add(usr)
            out |= self.all_overrides(usr)
        for count in f.indirect:
            out |= {usr for usr, params in self.address_taken.items() if params == count}
        for name in f.unresolved:
            for cls in self.instantiate:
                out |= self.methods_by_name.get((cls, name), set())
        return out

    def all_overrides(self, usr):
        seen, stack = set(), [usr]
        while stack:
            for o in self.overrides.get(stack.pop(), ()):
                if o not in seen:
                    seen.add(o)
                    stack.append(o)
        return seen

    def reachable(self, roots, exclude=()):
        seen, stack = set(), []
        for r in roots:
            matches = self.resolve(r)
            if not matches:
                print(f"warning: no definition of root {r}", file=sys.stderr)
            for m in matches:
                stack.append(m.usr)
        while stack:
            usr = stack.pop()
            if usr in seen or usr not in self.functions or self.functions[usr].name in exclude:
                continue
            seen.add(usr)
            stack.extend(self.callees(self.functions[usr]))
        return [self.functions[u] for u in seen]


def through_pointer(call):
    """Whether a call's callee is a variable, parameter or member holding a function pointer."""
    children = list(call.get_children())
    if not children:
        return False
    stack = [children[0]]
    while stack:
        c = stack.pop()
        if c.kind in (CK.DECL_REF_EXPR, CK.MEMBER_REF_EXPR):
            ref = c.referenced
            if ref is not None and ref.kind in (CK.VAR_DECL, CK.PARM_DECL, CK.FIELD_DECL):
                return "(*)" in ref.type.get_canonical().spelling
            if ref is not None:
                return False
        stack.extend(c.get_children())
    return False


def if_condition(cursor):
    toks = tokens_of(cursor)
    i = 1
    if i < len(toks) and toks[i] == "constexpr":
        i += 1
    if i >= len(toks) or toks[i] != "(":
        return []
    depth, j = 0, i
    while j < len(toks):
        depth += toks[j] == "("
        depth -= toks[j] == ")"
        if depth == 0:
            break
        j += 1
    cond = toks[i + 1:j]
    # `if (init; condition)`: the condition is after the top-level semicolon.
    depth = 0
    for k, t in enumerate(cond):
        depth += t in "([{"
        depth -= t in ")]}"
        if depth == 0 and t == ";":
            return cond[k + 1:]
    return cond


def sources(repo, folders):
    out = []
    for folder in folders:
        d = os.path.join(repo, folder)
        if os.path.isdir(d):
            out.extend(sorted(os.path.join(d, f) for f in os.listdir(d) if f.endswith(".cpp")))
    return out


def class_sizes(graph, folders):
    sizes = {}
    for usr, c in graph.classes.items():
        if not any(c["file"].startswith(f + "/") for f in folders):
            continue
        entry = dict(c)
        entry["lines"] += sum(f.lines for f in graph.functions.values() if f.class_usr == usr and f.out_of_line)
        sizes[c["name"]] = entry
    return sizes


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repo", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--root", action="append", help="a function to walk from (qualified); default: a string's step")
    ap.add_argument("--instantiate", action="append", default=None,
                    help="a class a template parameter's calls resolve to (default: PenaltyContact)")
    ap.add_argument("--json", help="write the figures here too")
    ap.add_argument("--programs", action="store_true",
                    help="also the decision points reachable from a step of each step program alone")
    ap.add_argument("--most", type=int, default=15, help="rows of the largest functions and classes")
    ap.add_argument("--libclang", default="/usr/lib/llvm-14/lib/libclang-14.so.1")
    a = ap.parse_args()
    if a.libclang and os.path.exists(a.libclang) and not ci.Config.loaded:
        ci.Config.set_library_file(a.libclang)
    repo = os.path.realpath(a.repo)
    folders = ["src/scheme", "src/numerics"]
    headers = ["include/fretbuzz/scheme", "include/fretbuzz/numerics"]
    args = ["-x", "c++", "-std=c++20", f"-I{repo}/include", f"-I{repo}/src", "-I/usr/include/eigen3",
            f"-I{repo}/build/generated/include"]
    instantiate = a.instantiate or ["PenaltyContact"]
    graph = Graph(repo, instantiate)
    graph.parse(sources(repo, folders), args)
    graph.link_overrides()
    roots = a.root or DEFAULT_ROOTS
    reached = graph.reachable(roots)
    reached.sort(key=lambda f: -f.decisions)
    total = sum(f.decisions for f in reached)
    deciding = [f for f in reached if f.decisions]
    by_atom = collections.defaultdict(set)
    for f in reached:
        for atom in f.atoms:
            by_atom[atom].add(f.name)
    repeated = {atom: sorted(names) for atom, names in by_atom.items() if len(names) > 1}
    sizes = class_sizes(graph, folders + headers)
    scheme_functions = [f for f in graph.functions.values() if any(f.file.startswith(d + "/") for d in folders + headers)]
    longest = max(scheme_functions, key=lambda f: f.lines)

    print(f"From {', '.join(roots)}:")
    print(f"  {len(reached)} functions reachable, {len(deciding)} of them deciding, {total} decision points")
    for f in reached[:a.most]:
        print(f"    {f.decisions:4d}  {f.name}  ({f.file}:{f.first})")
    print(f"  decisions taken in more than one function: {len(repeated)}")
    for atom, names in sorted(repeated.items(), key=lambda kv: (-len(kv[1]), kv[0])):
        print(f"    {atom}: {', '.join(names)}")
    per_program = {}
    if a.programs:
        print("  by step program (a step of that program alone; the same phases, the other programs' solves not entered):")
        for program in PROGRAMS:
            others = {f"fretbuzz::StepPrograms::{p}" for p in PROGRAMS if p != program}
            if not graph.resolve(f"fretbuzz::StepPrograms::{program}"):
                continue
            alone = graph.reachable(roots, exclude=others)
            per_program[program] = sum(f.decisions for f in alone)
            print(f"    {per_program[program]:4d}  {program} ({len(alone)} functions)")
    print(f"Classes in {', '.join(folders + headers)} (methods, lines), largest first:")
    ranked = sorted(sizes.values(), key=lambda c: (-c["methods"], -c["lines"]))
    for c in ranked[:a.most]:
        print(f"    {c['methods']:3d} {c['lines']:5d}  {c['name']}  ({c['file']})")
    over = [c for c in sizes.values() if c["methods"] > 20 or c["lines"] > 400]
    print(f"  over 20 methods or 400 lines: {', '.join(sorted(c['name'] for c in over)) or 'none'}")
    print(f"  longest function: {longest.name}, {longest.lines} lines ({longest.file}:{longest.first})")
    long_ones = sorted((f for f in scheme_functions if f.lines >= 80), key=lambda f: -f.lines)
    for f in long_ones:
        print(f"    {f.lines:4d} lines  {f.name}  ({f.file}:{f.first})")
    if a.json:
        with open(a.json, "w") as out:
            json.dump({
                "roots": roots,
                "reachable": len(reached),
                "decision_points": total,
                "functions": [{"name": f.name, "file": f.file, "line": f.first, "decisions": f.decisions}
                              for f in reached],
                "repeated_decisions": repeated,
                "classes": ranked,
                "longest_function": {"name": longest.name, "lines": longest.lines, "file": longest.file},
                "functions_of_80_lines_or_more": [{"name": f.name, "lines": f.lines} for f in long_ones],
                "by_program": per_program,
            }, out, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
