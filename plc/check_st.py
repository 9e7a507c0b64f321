#!/usr/bin/env python3
"""Checks the Structured Text of plc/src against two real parsers and the C header.

Run by tests/plc.rs (in a venv with blark==0.8.3, tree-sitter and
tree-sitter-iec61131-3-st==0.1.2):

    python plc/check_st.py [--src plc/src] [--header include/delta_collide.h]
                           [--readme plc/README.md]

1. Every .st file parses without error with blark and with tree-sitter, and two broken copies
   of each (its first END_ keyword misspelt; the `:` of its first declaration written `=`)
   fail both.
2. blark's and tree-sitter's readings of the declarations agree: the external functions, the
   structs, the function blocks' VAR_INPUT and VAR_OUTPUT, the global constants.
3. Those declarations agree with the header: each external's name (and external_name
   pragma), result type, parameter names in order and types; each ST_DcX struct's fields
   against struct DcX; each constant's value; the types mapped by the table of
   plc/README.md, "Types". Each call of an external names all its parameters in order.
4. Every DC_STATUS_* of the header is a CASE label of F_DcKnownStatus and a row of the
   ErrorID table in plc/README.md, with the ErrorID and DiagCodes of the documented rule;
   every DiagCode the code sets is a row of the README's DiagCode table.
5. The transitions that FB_DeltaCollide and FB_DeltaProtect take (each `Transition := N`
   right after a `State := E_DcFbState.X` inside a CASE on State) are exactly the rows of the
   transition table in plc/README.md, "State machine".

Prints one line per failed check (`FAIL: ...`) and ends with `check_st: N passed, M failed`;
exits 1 when a check failed.
"""

import argparse
import pathlib
import re
import sys

import tree_sitter
import tree_sitter_iec61131_3_st
from blark.parse import parse_source_code
from blark.summary import CodeSummary

PASSED = 0
FAILED = 0

# C names that are IEC 61131-3 (or CODESYS/TwinCAT) keywords take this prefix in ST.
KEYWORD_PREFIX = "c_"
IEC_KEYWORDS = {"time", "method", "date", "string", "type", "array", "struct", "var"}

# The function blocks' inputs and outputs that stand for a C entity: ("param", function,
# parameter) is that parameter's mapped type, ("pointee", ...) the type it points to,
# ("tcps", ...) an array of DC_MAX_ROBOTS of the pointee; other entries are fixed ST types.
COMMON_IN = [
    ("Enable", "BOOL"),
    ("Reset", "BOOL"),
    ("pConfig", ("param", "dc_init", "config")),
    ("pTable", ("param", "dc_init_with_table", "table")),
    ("TableLen", ("param", "dc_init_with_table", "table_len")),
    ("CellFile", "STRING(255)"),
    ("TableFile", "STRING(255)"),
    ("NumRobots", "UDINT"),
    ("Tcps", ("tcps", "dc_query", "tcps_mcs")),
]
PLCOPEN_OUT = [
    ("Valid", "BOOL"),
    ("Busy", "BOOL"),
    ("Error", "BOOL"),
    ("ErrorID", "UDINT"),
    ("DiagCode", "WORD"),
]
FB_INTERFACES = {
    "FB_DeltaCollide": (
        COMMON_IN,
        PLCOPEN_OUT
        + [
            ("Verdict", ("pointee", "dc_query", "out_verdict")),
            ("Free", "BOOL"),
            ("Report", ("pointee", "dc_query", "out_report")),
            ("InitMessage", "STRING(255)"),
        ],
    ),
    "FB_DeltaProtect": (
        COMMON_IN
        + [
            ("TickMs", ("param", "dc_set_stop_model", "tick_ms")),
            ("WarnMm", ("param", "dc_set_stop_model", "warn_mm")),
            ("StopModels", ("tcps", "dc_set_stop_model", "stops")),
            ("SpeedLimits", "BOOL"),
            ("Cycle", ("field", "DcProtectiveRequest", "time")),
            ("Coordinate", "BOOL"),
            ("pProgrammes", ("field", "DcCoordinationRequest", "programmes")),
        ],
        PLCOPEN_OUT
        + [
            ("Verdict", ("pointee", "dc_protective_query_timed", "out_verdict")),
            ("Free", "BOOL"),
            ("Report", ("pointee", "dc_protective_query_timed", "out_report")),
            ("Overrides", ("tcps", "dc_coordinate", "out_overrides")),
            ("Coordination", ("tcps", "dc_coordinate", "out_robots")),
            ("InitMessage", "STRING(255)"),
        ],
    ),
}


def check(ok, what):
    global PASSED, FAILED
    if ok:
        PASSED += 1
    else:
        FAILED += 1
        print(f"FAIL: {what}")
    return ok


def first_difference(got, want):
    """Where two lists first differ, for a message that names the change."""
    for i, (g, w) in enumerate(zip(got, want)):
        if g != w:
            return f"#{i}: {g} where the header has {w}"
    return f"lengths {len(got)} and {len(want)}"


def norm_type(text):
    """One spelling of an ST type: single spaces, none inside brackets and parentheses."""
    t = re.sub(r"\s+", " ", text.strip())
    t = re.sub(r"\s*\[\s*", "[", t)
    t = re.sub(r"\s*\]\s*", "] ", t).strip()
    t = re.sub(r"\s*\.\.\s*", "..", t)
    t = re.sub(r"\s*\(\s*", "(", t)
    t = re.sub(r"\s*\)", ")", t)
    return t.upper()


def st_name(c_name):
    return KEYWORD_PREFIX + c_name if c_name.lower() in IEC_KEYWORDS else c_name


def st_int(text):
    text = text.strip().replace("_", "")
    if "#" in text:
        base, digits = text.split("#", 1)
        return int(digits, int(base))
    return int(text)


# ------------------------------------------------------------------ the header


def parse_header(path):
    text = re.sub(r"/\*.*?\*/", "", pathlib.Path(path).read_text(), flags=re.S)
    typedefs = dict(
        (alias, base)
        for base, alias in re.findall(r"typedef\s+(u?int\d+_t|double|size_t)\s+(\w+);", text)
    )
    defines = {}
    for name, value in re.findall(r"#define\s+(DC_\w+)\s+(\S+)", text):
        if value == "UINT32_MAX":
            defines[name] = 0xFFFFFFFF
        elif re.fullmatch(r"-?\d+", value):
            defines[name] = int(value)
    structs = {}
    for name, body in re.findall(r"typedef struct (\w+) \{(.*?)\} \1;", text, flags=re.S):
        fields = []
        for decl in body.split(";"):
            decl = " ".join(decl.split())
            if not decl:
                continue
            m = re.fullmatch(r"(.+?)\s*(\w+)(?:\[(\d+)\])?", decl)
            fields.append((m.group(2), m.group(1).strip(), int(m.group(3)) if m.group(3) else None))
        structs[name] = fields
    functions = {}
    for ret, name, params in re.findall(r"^([\w ]+?[ *]+)(dc_\w+)\(([^)]*)\);", text, flags=re.M):
        plist = []
        for p in params.split(","):
            p = " ".join(p.split())
            if p in ("", "void"):
                continue
            m = re.fullmatch(r"(.+?)\s*(\w+)", p)
            plist.append((m.group(2), m.group(1).strip()))
        functions[name] = (ret.strip(), plist)
    return typedefs, defines, structs, functions


def read_scalar_types(readme):
    """The scalar rows of plc/README.md's type table: | `C type` | `ST type` | ..."""
    section = readme.split("### Types", 1)[1].split("\n#", 1)[0]
    table = {}
    for c, st in re.findall(r"^\| `([^`]+)` \| `([^`]+)` \|", section, flags=re.M):
        table[c] = st
    return table


class Mapper:
    """C types of the header to ST types, by the README's table and the pointer, struct and
    array rules it states."""

    def __init__(self, typedefs, scalars):
        self.typedefs = typedefs
        self.scalars = scalars

    def map(self, ctype, array_len=None):
        if array_len is not None:
            return f"ARRAY[0..{array_len - 1}] OF {self.map(ctype)}"
        t = " ".join(ctype.replace("const ", "").replace("struct ", "").split())
        t = re.sub(r"\s*\*", "*", t)
        if t in self.scalars:
            return self.scalars[t]
        if t.endswith("*"):
            return "POINTER TO " + self.map(t[:-1])
        if t in self.typedefs:
            return self.map(self.typedefs[t])
        if re.fullmatch(r"Dc\w+", t):
            return "ST_" + t
        raise KeyError(f"C type `{ctype}` has no row in plc/README.md's type table")

    def pointee(self, ctype):
        t = ctype.replace("const ", "").strip()
        assert t.endswith("*"), ctype
        return self.map(t[:-1])


# ------------------------------------------------------------------ the parsers


def blark_parse(path, source):
    result = parse_source_code(source, fn=str(path))
    return result


def ts_parser():
    return tree_sitter.Parser(tree_sitter.Language(tree_sitter_iec61131_3_st.language()))


def ts_errors(node):
    out = []
    if node.type == "ERROR" or node.is_missing:
        out.append(f"{node.type} at line {node.start_point[0] + 1}")
    for c in node.children:
        out.extend(ts_errors(c))
    return out


def txt(node):
    return node.text.decode()


def ts_decls(block):
    """(name, type) of each variable_declaration of a var block node, in order."""
    out = []
    for d in block.named_children:
        if d.type != "variable_declaration":
            continue
        for n in d.children_by_field_name("names"):
            out.append((txt(n), norm_type(txt(d.child_by_field_name("type")))))
    return out


def ts_read(root):
    """What tree-sitter reads: externals, structs, FB interfaces, globals."""
    functions, structs, fbs, consts = {}, {}, {}, {}
    pragma = None
    for node in root.named_children:
        if node.type == "pragma":
            m = re.search(r"external_name'\s*:=\s*'(\w+)'", txt(node))
            pragma = m.group(1) if m else None
            continue
        if node.type == "function_declaration":
            name = txt(node.child_by_field_name("name"))
            ret = node.child_by_field_name("return_type")
            inputs = [d for b in node.named_children if b.type == "var_input" for d in ts_decls(b)]
            body = node.children_by_field_name("body")
            functions[name] = (pragma, norm_type(txt(ret)), inputs, len(body))
        elif node.type == "function_block_declaration":
            name = txt(node.child_by_field_name("name"))
            ins = [d for b in node.named_children if b.type == "var_input" for d in ts_decls(b)]
            outs = [d for b in node.named_children if b.type == "var_output" for d in ts_decls(b)]
            fbs[name] = (ins, outs)
        elif node.type == "type_declaration":
            for td in node.named_children:
                definition = td.child_by_field_name("definition")
                if definition is not None and definition.type == "structure_type_inline":
                    fields = [
                        (txt(f.child_by_field_name("name")),
                         norm_type(txt(f.child_by_field_name("type"))))
                        for f in definition.named_children
                        if f.type == "structure_field"
                    ]
                    structs[txt(td.child_by_field_name("name"))] = fields
        elif node.type == "global_var_declaration_block":
            for vg in node.named_children:
                for d in vg.named_children:
                    if d.type == "variable_declaration":
                        value = d.child_by_field_name("initial_value")
                        for n in d.children_by_field_name("names"):
                            consts[txt(n)] = st_int(txt(value))
        if node.type != "comment":
            pragma = None
    return functions, structs, fbs, consts


def blark_read(summary):
    functions, structs, fbs, consts = {}, {}, {}, {}
    for name, f in summary.functions.items():
        pragmas = [str(c) for c in (f.item.meta.comments or [])]
        m = re.search(r"external_name'\s*:=\s*'(\w+)'", " ".join(pragmas))
        inputs = [(d.name, norm_type(d.type)) for d in f.declarations.values()
                  if d.block == "VAR_INPUT"]
        body = f.item.body
        n_body = len(body.statements) if body is not None else 0
        functions[f.item.name] = (m.group(1) if m else None, norm_type(f.return_type or ""),
                                  inputs, n_body)
    for name, fb in summary.function_blocks.items():
        ins = [(d.name, norm_type(d.type)) for d in fb.declarations.values()
               if d.block == "VAR_INPUT"]
        outs = [(d.name, norm_type(d.type)) for d in fb.declarations.values()
                if d.block == "VAR_OUTPUT"]
        fbs[fb.item.name] = (ins, outs)
    for name, dt in summary.data_types.items():
        if dt.type == "StructureTypeDeclaration":
            structs[name] = [(d.name, norm_type(d.type)) for d in dt.declarations.values()]
    for gvl in summary.globals.values():
        for d in gvl.declarations.values():
            consts[d.name] = st_int(d.value)
    return functions, structs, fbs, consts


# ------------------------------------------------------------------ checks


def broken_copies(text):
    """Copies that no parser may accept: the first END_ keyword misspelt, the `:` of the
    first declaration written `=`."""
    m = re.search(r"\bEND_(\w+)", text)
    yield "misspelt " + m.group(0), text[: m.start()] + "END_X" + m.group(1) + text[m.end():]
    m = re.search(r"^( *\w+) : ", text, flags=re.M)
    yield f"`{m.group(1).strip()} = ...`", text[: m.end(1)] + " = " + text[m.end():]


def parse_all(src_dir):
    parser = ts_parser()
    results, trees = [], {}
    files = sorted(pathlib.Path(src_dir).glob("*.st"))
    check(len(files) >= 6, f"{src_dir}: expected the six .st files, found {len(files)}")
    rejected = 0
    for path in files:
        source = path.read_text()
        result = blark_parse(path, source)
        check(result.exception is None, f"blark cannot parse {path.name}: {result.exception}")
        results.append(result)
        tree = parser.parse(source.encode())
        errs = ts_errors(tree.root_node)
        check(not tree.root_node.has_error, f"tree-sitter finds errors in {path.name}: {errs}")
        trees[path.name] = tree
        for what, broken in broken_copies(source):
            b = blark_parse(path, broken).exception is not None
            t = parser.parse(broken.encode()).root_node.has_error
            rejected += b and t
            check(b, f"blark accepts a broken copy of {path.name} ({what})")
            check(t, f"tree-sitter accepts a broken copy of {path.name} ({what})")
    print(f"parsed {len(files)} files with blark and tree-sitter; "
          f"broken copies rejected by both: {rejected} of {2 * len(files)}")
    return results, trees


def merged_ts(trees):
    functions, structs, fbs, consts = {}, {}, {}, {}
    for tree in trees.values():
        f, s, b, c = ts_read(tree.root_node)
        functions.update(f)
        structs.update(s)
        fbs.update(b)
        consts.update(c)
    return functions, structs, fbs, consts


def check_externals(functions, header_functions, mapper):
    externals = {n: f for n, f in functions.items() if f[0] is not None}
    check(len(externals) >= 10, f"expected the external declarations, found {sorted(externals)}")
    for name, (pragma, ret, inputs, n_body) in externals.items():
        check(pragma == name, f"{name}: external_name '{pragma}' differs from the name")
        check(n_body == 0, f"{name}: an external declaration has no body")
        if not check(pragma in header_functions, f"{name}: no function {pragma} in the header"):
            continue
        c_ret, c_params = header_functions[pragma]
        check(ret == norm_type(mapper.map(c_ret)),
              f"{name}: result {ret}, the header's `{c_ret}` maps to {mapper.map(c_ret)}")
        want = [(st_name(p), norm_type(mapper.map(t))) for p, t in c_params]
        check(inputs == want, f"{name}: parameter {first_difference(inputs, want)}")
    return externals


def check_structs(structs, header_structs, mapper):
    for st, fields in structs.items():
        c = st[3:] if st.startswith("ST_") else None
        if not check(c in header_structs, f"{st}: no struct {c} in the header"):
            continue
        want = [(st_name(f), norm_type(mapper.map(t, n))) for f, t, n in header_structs[c]]
        check(fields == want, f"{st}: field {first_difference(fields, want)}")
    check(len(structs) >= 10, f"expected the ST_Dc structs, found {sorted(structs)}")


def check_constants(consts, defines):
    for name, value in consts.items():
        if name.startswith("DC_"):
            check(defines.get(name) == value,
                  f"constant {name} = {value}, the header says {defines.get(name)}")
    for name, value in defines.items():
        if name.startswith(("DC_STATUS_", "DC_VERDICT_", "DC_CLOCK_")) or name == "DC_MAX_ROBOTS":
            check(name in consts, f"the header's {name} ({value}) is not in GVL_DeltaCollide")
    own = [v for n, v in consts.items() if n.startswith("DCFB_ERR_")]
    statuses = [v for n, v in defines.items() if n.startswith("DC_STATUS_")]
    check(own and min(own) > max(statuses), "the blocks' own ErrorIDs lie above every status")


def check_fb_interfaces(fbs, header_functions, header_structs, mapper, max_robots):
    def expected(spec):
        if isinstance(spec, str):
            return norm_type(spec)
        kind, a, b = spec
        if kind == "field":
            ctype = dict((f, t) for f, t, _ in header_structs[a])[b]
            return norm_type(mapper.map(ctype))
        ctype = dict(header_functions[a][1])[b]
        if kind == "param":
            return norm_type(mapper.map(ctype))
        if kind == "pointee":
            return norm_type(mapper.pointee(ctype))
        return norm_type(f"ARRAY[0..{max_robots - 1}] OF {mapper.pointee(ctype)}")

    for fb, (ins, outs) in FB_INTERFACES.items():
        if not check(fb in fbs, f"no function block {fb}"):
            continue
        got_in, got_out = fbs[fb]
        want_in = [(n, expected(s)) for n, s in ins]
        want_out = [(n, expected(s)) for n, s in outs]
        check(got_in == want_in, f"{fb} VAR_INPUT {first_difference(got_in, want_in)}")
        check(got_out == want_out, f"{fb} VAR_OUTPUT {first_difference(got_out, want_out)}")


def walk(node):
    yield node
    for c in node.children:
        yield from walk(c)


def check_calls(trees, externals):
    """Each call of an external passes every parameter by name, in the declared order."""
    calls = {}
    for file, tree in trees.items():
        for n in walk(tree.root_node):
            if n.type != "call_expression":
                continue
            fname = txt(n.child_by_field_name("function"))
            if fname not in externals:
                continue
            args = n.child_by_field_name("arguments")
            names = [txt(a.child_by_field_name("name")) for a in args.named_children
                     if a.type == "named_argument"]
            want = [p for p, _ in externals[fname][2]]
            check(names == want, f"{file}: call of {fname} passes {names}, declared {want}")
            calls[fname] = calls.get(fname, 0) + 1
    for name in externals:
        check(name in calls, f"external {name} is declared but never called")


def check_status_mapping(trees, defines, readme):
    statuses = {n: v for n, v in defines.items() if n.startswith("DC_STATUS_")}
    labels = set()
    for tree in trees.values():
        for n in walk(tree.root_node):
            if n.type == "function_declaration" and txt(n.child_by_field_name("name")) == \
                    "F_DcKnownStatus":
                for cv in walk(n):
                    if cv.type == "case_value":
                        labels.add(txt(cv))
    check(labels == set(statuses),
          f"F_DcKnownStatus labels differ from the header's statuses: missing "
          f"{sorted(set(statuses) - labels)}, extra {sorted(labels - set(statuses))}")
    rows = re.findall(r"^\| (\d+) \| `(DC_STATUS_\w+)` \| ([^|]+) \| ([^|]+) \| ([^|]+) \|",
                      readme, flags=re.M)
    documented = {name: (int(num), e.strip(), i.strip(), q.strip())
                  for num, name, e, i, q in rows}
    for name, value in statuses.items():
        if not check(name in documented, f"{name} has no row in plc/README.md's ErrorID table"):
            continue
        num, error_id, at_init, in_query = documented[name]
        check(num == value, f"README: {name} is {num}, the header says {value}")
        if value == 0:
            check(error_id == "0", f"README: ErrorID of {name} is {error_id}")
            continue
        check(error_id == str(value), f"README: ErrorID of {name} is {error_id}, not {value}")
        check(at_init == f"16#C1{value:02X}", f"README: init DiagCode of {name} is {at_init}")
        check(in_query == f"16#C2{value:02X}", f"README: query DiagCode of {name} is {in_query}")
    check(set(documented) <= set(statuses),
          f"README documents statuses the header lacks: {sorted(set(documented) - set(statuses))}")


def check_diag_codes(trees, readme):
    """Every DiagCode the code can set is a row of plc/README.md's DiagCode table: the
    literals assigned to DiagCode in the blocks, and the bases F_DcDiagError combines with
    an ErrorID (16#C100 OR id is the row 16#C1xx)."""
    section = readme.split("### ErrorID and DiagCode", 1)[1]
    documented = set(re.findall(r"^\| (16#[0-9A-Fa-fx]{4}) \|", section, flags=re.M))
    found = set()
    for tree in trees.values():
        for n in walk(tree.root_node):
            if n.type != "assignment_statement":
                continue
            left = txt(n.child_by_field_name("left"))
            if left not in ("DiagCode", "F_DcDiagError"):
                continue
            right = n.child_by_field_name("right")
            if right.type == "integer_literal":
                found.add(f"16#{st_int(txt(right)):04X}")
            elif right.type == "binary_expression":
                base = st_int(txt(right.child_by_field_name("left")))
                found.add(f"16#{base >> 8:02X}xx")
    check(len(found) >= 8, f"DiagCodes found in the code: {sorted(found)}")
    for code in sorted(found):
        check(code in documented, f"DiagCode {code} is set by the code but has no row in the README")
    print(f"DiagCodes set by the code, each documented: {' '.join(sorted(found))}")


def read_transition_table(readme):
    section = readme.split("### State machine", 1)[1].split("\n#", 1)[0]
    rows = re.findall(r"^\| T(\d+) \| (\w+) \| [^|]+ \| (\w+) \|", section, flags=re.M)
    return {(int(n), a, b) for n, a, b in rows}


def fb_transitions(fb_node):
    """(row, from, to) of each `State := E_DcFbState.X; Transition := N;` in a CASE on
    State, `from` the CASE label around it."""
    found = []
    for n in walk(fb_node):
        if n.type != "assignment_statement" or txt(n.child_by_field_name("left")) != "Transition":
            continue
        prev = n.prev_named_sibling
        while prev is not None and prev.type == "comment":
            prev = prev.prev_named_sibling
        to = None
        if prev is not None and prev.type == "assignment_statement" and \
                txt(prev.child_by_field_name("left")) == "State":
            to = txt(prev.child_by_field_name("right")).split(".")[-1]
        clause = n.parent
        while clause is not None and clause.type != "case_clause":
            clause = clause.parent
        frm = None
        if clause is not None and txt(clause.parent.child_by_field_name("subject")) == "State":
            values = [txt(c) for c in clause.named_children if c.type == "case_value"]
            frm = values[0].split(".")[-1] if len(values) == 1 else None
        row = st_int(txt(n.child_by_field_name("right")))
        found.append((row, frm, to, n.start_point[0] + 1))
    return found


def check_transitions(trees, readme):
    table = read_transition_table(readme)
    check(len(table) >= 9, f"plc/README.md's transition table has {len(table)} rows")
    for tree in trees.values():
        for node in tree.root_node.named_children:
            if node.type != "function_block_declaration":
                continue
            fb = txt(node.child_by_field_name("name"))
            found = fb_transitions(node)
            for row, frm, to, line in found:
                check((row, frm, to) in table,
                      f"{fb} line {line}: T{row} {frm} -> {to} is not a row of the table")
            rows = {(r, f, t) for r, f, t, _ in found}
            check(rows == table, f"{fb}: rows of the table it never takes: {sorted(table - rows)}")
            print(f"{fb}: {len(found)} transitions, rows {sorted(r for r, _, _ in rows)}")


def main():
    here = pathlib.Path(__file__).resolve().parent
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--src", default=here / "src")
    ap.add_argument("--header", default=here.parent / "include" / "delta_collide.h")
    ap.add_argument("--readme", default=here / "README.md")
    args = ap.parse_args()
    readme = pathlib.Path(args.readme).read_text()
    typedefs, defines, header_structs, header_functions = parse_header(args.header)
    mapper = Mapper(typedefs, read_scalar_types(readme))

    results, trees = parse_all(args.src)
    summary = CodeSummary.from_parse_results(results)
    b_functions, b_structs, b_fbs, b_consts = blark_read(summary)
    t_functions, t_structs, t_fbs, t_consts = merged_ts(trees)
    # The two parsers read the same declarations (names, order, types).
    for what, b, t in [("functions", b_functions, t_functions), ("structs", b_structs, t_structs),
                       ("function blocks", b_fbs, t_fbs), ("constants", b_consts, t_consts)]:
        differ = sorted(k for k in set(b) | set(t) if b.get(k) != t.get(k))
        check(not differ and b, f"{what}: blark and tree-sitter read differently: {differ}")

    try:
        externals = check_externals(t_functions, header_functions, mapper)
        check_structs(t_structs, header_structs, mapper)
        check_constants(t_consts, defines)
        check_fb_interfaces(t_fbs, header_functions, header_structs, mapper,
                            defines["DC_MAX_ROBOTS"])
        check_calls(trees, externals)
    except KeyError as e:
        check(False, str(e))
        externals = {}
    check_status_mapping(trees, defines, readme)
    check_diag_codes(trees, readme)
    check_transitions(trees, readme)
    print(f"externals checked against the header: {', '.join(sorted(externals))}")
    print(f"check_st: {PASSED} passed, {FAILED} failed")
    return 1 if FAILED else 0


if __name__ == "__main__":
    sys.exit(main())
