#!/usr/bin/env python3
"""Fails if the library's sources read /proc or hold process-global mutable state.

Usage: check_library_state.py ROOT [DIR ...]   (default DIRs: residuals estimator config)
       check_library_state.py --self-test

Scans every .h and .cc file under ROOT/DIR (comments and string contents
aside, except that a string naming /proc counts) for:
  - "/proc": the library reads nothing of the machine's state;
  - a `static` or `thread_local` variable (namespace, class or function scope)
    that is not `constexpr` or `const` (for a pointer: const before its first
    `*` or `&`, so `static Foo* const` still counts as mutable);
  - a variable at namespace scope that is not `constexpr` or `const` in the
    same sense.
Static functions, `static constexpr`, `static const`, `inline constexpr`, and
types, usings and function declarations are allowed. Prints each finding as
`file:line: what` and exits 1 if there is any, 0 otherwise.

The parse is a brace-and-statement scan, not a compiler: a mutable variable
declared with parentheses and a parameter-like argument (`static Foo f(Bar
b);`, which C++ itself reads as a function declaration) is not seen.
--self-test runs the scan on snippets with and without such state and exits 1
unless each is classified as expected.
"""

import os
import re
import sys
import tempfile

KEYWORDS_NOT_VARIABLES = ("using", "typedef", "template", "class", "struct", "union", "enum",
                          "friend", "static_assert", "namespace", "extern", "__classtail__")


def strip_comments_and_strings(text):
    """Returns (code, proc_lines): code with comments blanked and string and
    character literals emptied (newlines kept), and the lines of literals or
    code that name /proc."""
    out = []
    proc_lines = set()
    i, n, line = 0, len(text), 1
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            out.append(c)
            i += 1
        elif text.startswith("//", i):
            while i < n and text[i] != "\n":
                i += 1
        elif text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = n if end < 0 else end + 2
            newlines = text.count("\n", i, end)
            line += newlines
            out.append("\n" * newlines)
            i = end
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not text[i - 1].isalnum()):
            open_paren = text.find("(", i)
            delimiter = text[i + 2:open_paren]
            end = text.find(")" + delimiter + '"', open_paren)
            end = n if end < 0 else end + len(delimiter) + 2
            literal = text[i:end]
            if "/proc" in literal:
                proc_lines.add(line)
            newlines = literal.count("\n")
            line += newlines
            out.append('""' + "\n" * newlines)
            i = end
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            if "/proc" in text[i:j]:
                proc_lines.add(line)
            out.append(c + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    code = "".join(out)
    for number, code_line in enumerate(code.split("\n"), 1):
        if "/proc" in code_line:
            proc_lines.add(number)
    # Preprocessor lines (with continuations) are no declarations.
    code = re.sub(r"(?m)^[ \t]*#(?:[^\n]*\\\n)*[^\n]*", lambda m: "\n" * m.group(0).count("\n"),
                  code)
    return code, proc_lines


def top_level(text, stop_chars):
    """The prefix of `text` before the first of `stop_chars` outside (), <>, []."""
    depth = 0
    for k, c in enumerate(text):
        if c in "([<":
            depth += 1
        elif c in ")]>":
            depth = max(0, depth - 1)
        elif depth == 0 and c in stop_chars:
            if c == "=" and (text[k - 1:k] in ("=", "!", "<", ">") or text[k + 1:k + 2] == "="
                             or re.search(r"operator\s*\S?$", text[:k])):
                continue
            return text[:k]
    return text


def is_function_declarator(declaration):
    """Whether a declaration (before its initializer) declares a function:
    parentheses whose content is empty, `void`, or a parameter list (a type
    followed by a name, or a type with * or &)."""
    match = re.search(r"\(([^()]*)\)", declaration)
    if not match:
        return False
    inside = match.group(1).strip()
    if inside in ("", "void"):
        return True
    return bool(re.search(r"[A-Za-z_>\]][\s*&]+[A-Za-z_]", inside))


def is_const_declaration(declaration):
    """Whether the variable declared is constexpr or const (for a pointer or
    reference: const before its first * or &)."""
    tokens = re.findall(r"[A-Za-z_]\w*", declaration)
    if "constexpr" in tokens:
        return True
    before_indirection = re.split(r"[*&]", declaration, maxsplit=1)[0]
    return "const" in re.findall(r"[A-Za-z_]\w*", before_indirection)


def mutable_variable(statement, require_static):
    """The finding for `statement` (declaration text up to its initializer or
    end) if it declares a mutable variable: with `require_static`, only a
    static or thread_local one."""
    declaration = top_level(statement, "={;").strip()
    tokens = re.findall(r"[A-Za-z_]\w*", declaration)
    is_static = "static" in tokens or "thread_local" in tokens
    if require_static and not is_static:
        return None
    if not tokens or (not require_static and tokens[0] in KEYWORDS_NOT_VARIABLES):
        return None
    if tokens[0] in ("return", "typedef", "using", "friend", "static_assert", "else", "case"):
        return None
    if require_static and any(t in ("class", "struct", "enum", "union") for t in tokens[:2]):
        return None
    if is_function_declarator(declaration) or "operator" in tokens:
        return None
    if len(tokens) < 2 and "static" not in tokens:
        return None  # an expression statement or a label
    if is_const_declaration(declaration):
        return None
    kind = "static or thread_local" if is_static else "namespace-scope"
    return "mutable %s variable: %s" % (kind, " ".join(declaration.split()))


def classify_brace(statement, parent):
    """What a `{` opens after `statement` in a scope of kind `parent`."""
    s = statement.strip()
    if parent in ("init", "func"):
        return parent
    if re.match(r"(inline\s+)?namespace\b", s) or re.match(r'extern\s*""', s):
        return "ns"
    if re.search(r"=", top_level(s + ";", ";")) and "(" not in top_level(s, "="):
        return "init"
    if top_level(s, "=") != s and not re.search(r"\)\s*(const|override|final|noexcept|\s)*$", s):
        return "init"
    if (re.match(r"(template\s*<.*>\s*)?(class|struct|union|enum)\b", s) and "(" not in s):
        return "class"
    if re.search(r"[A-Za-z_\]>]\s*$", s) and "(" not in s:
        return "init"  # Type name{...}
    return "func"


def scan(path, text):
    """The findings in one file's text, as (line, message)."""
    code, proc_lines = strip_comments_and_strings(text)
    findings = {line: "reads /proc" for line in proc_lines}
    stack = [("ns", "", 0)]
    statement, start_line, line = "", 1, 1

    def report(message, at):
        if message:
            findings.setdefault(at, message)

    for c in code:
        if c == "\n":
            line += 1
            statement += " "
            continue
        kind = stack[-1][0]
        if not statement.strip():
            start_line = line
        if c == "{":
            if kind in ("ns", "class", "func"):
                report(mutable_variable(statement, True), start_line)
            opened = classify_brace(statement, kind)
            if opened == "init":
                stack.append(("init", statement + "{", start_line))
                statement = ""
            else:
                stack.append((opened, statement, start_line))
                statement = ""
        elif c == "}":
            if len(stack) == 1:
                continue
            closed, saved, saved_line = stack.pop()
            if closed == "init":
                statement, start_line = saved + "}", saved_line
            elif closed == "class":
                statement, start_line = "__classtail__ ", line
            else:
                statement = ""
        elif c == ";":
            if kind in ("ns", "class", "func"):
                report(mutable_variable(statement, True), start_line)
                if kind == "ns" and not statement.strip().startswith("__classtail__"):
                    report(mutable_variable(statement, False), start_line)
            if kind != "init":
                statement = ""
        elif kind != "init":
            statement += c
    return sorted(findings.items())


def check(root, directories):
    count = 0
    for directory in directories:
        for folder, _, files in sorted(os.walk(os.path.join(root, directory))):
            for name in sorted(files):
                if not name.endswith((".h", ".cc")):
                    continue
                path = os.path.join(folder, name)
                with open(path, encoding="utf-8") as source:
                    for number, message in scan(path, source.read()):
                        print("%s:%d: %s" % (os.path.relpath(path, root), number, message))
                        count += 1
    return count


# Snippets the scan must flag (True) or pass (False).
SELF_TEST_CASES = [
    (True, "namespace a {\nstd::atomic<bool> started{false};\n}\n"),
    (True, "namespace {\nint calls = 0;\n}\n"),
    (True, "namespace a {\nstd::vector<int> cache;\n}\n"),
    (True, "int Count() {\n  static int calls = 0;\n  return ++calls;\n}\n"),
    (True, "void F() {\n  static std::mutex lock;\n}\n"),
    (True, "Foo& F() {\n  static Foo* const foo = new Foo;\n  return *foo;\n}\n"),
    (True, "struct S {\n  static S histories[8];\n  int x = 0;\n};\n"),
    (True, "void F() {\n  thread_local int depth = 0;\n}\n"),
    (True, "void F() {\n  static std::atomic<int> n{0};\n}\n"),
    (True, "int F() {\n  return open(\"/proc/loadavg\", 0);\n}\n"),
    (True, 'const char* kPath = R"(/proc/self/stat)";\n'),
    (False, "namespace a {\nconstexpr int kRows = 256;\nconst double kPi = 3.14;\n}\n"),
    (False, "namespace {\nconst char* const kNames[] = {\"a\", \"b\"};\n}\n"),
    (False, "namespace a {\ninline constexpr int kKinds = 8;\nstatic int Helper(int x);\n}\n"),
    (False, "static bool Local(const Foo& foo) {\n  int calls = 0;\n  return calls > 0;\n}\n"),
    (False, "class C {\n public:\n  static constexpr int kA = 1;\n  static const int kB;\n"
     "  static C Make(int a, double b);\n  int count_ = 0;\n  bool ok() const { return x; }\n};\n"),
    (False, "int F(int a = 1) {\n  int x{3};\n  std::vector<int> v = {1, 2};\n  return x;\n}\n"),
    (False, "namespace a {\nusing Probe = int (*)();\nint Declared(int a, double* b);\n"
     "template <typename T>\nT Twice(const T& t) {\n  return t + t;\n}\nstruct Fwd;\n}\n"),
    (False, "Foo::Foo(int a) : a_(a), b_{a} {\n  static_assert(sizeof(int) == 4, \"\");\n}\n"),
    (False, "// reads /proc/loadavg in a comment only\nint x();\n"),
    (False, "namespace {\nconst auto kTable = [] {\n  std::array<int, 3> t{};\n  return t;\n}();\n}\n"),
    (False, "enum class Kind { kA, kB };\nstruct P {\n  double v = 0.0;\n} ;\n"),
]


def self_test():
    failures = 0
    with tempfile.TemporaryDirectory() as directory:
        for index, (should_flag, snippet) in enumerate(SELF_TEST_CASES):
            path = os.path.join(directory, "case_%d.cc" % index)
            with open(path, "w", encoding="utf-8") as out:
                out.write(snippet)
            flagged = check(directory, ["."]) > 0
            os.remove(path)
            if flagged != should_flag:
                failures += 1
                print("self-test case %d: expected %s, got %s:\n%s" %
                      (index, "a finding" if should_flag else "none",
                       "a finding" if flagged else "none", snippet))
    if failures:
        print("self-test FAILED: %d of %d cases not as expected" % (failures, len(SELF_TEST_CASES)))
        return 1
    print("self-test: all %d cases as expected" % len(SELF_TEST_CASES))
    return 0


def main(argv):
    if argv[1:] == ["--self-test"]:
        return self_test()
    if len(argv) < 2:
        print(__doc__)
        return 2
    directories = argv[2:] or ["residuals", "estimator", "config"]
    count = check(argv[1], directories)
    print("%d finding(s) in %s" % (count, ", ".join(directories)))
    return 1 if count else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
