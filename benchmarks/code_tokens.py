"""Count the code tokens of a Python package: its size with comments, docstrings and layout left out.

A token is one of Python's tokens (names, operators, numbers, strings). Comments, docstrings (the first
statement of a module, class or function when it is a string) and layout tokens (NEWLINE, NL, INDENT, DEDENT,
ENCODING, ENDMARKER) are not counted, so a formatter cannot move the count.

    python benchmarks/code_tokens.py                       # src/geardyn: total and per package
    python benchmarks/code_tokens.py --files 20            # and the 20 largest files
    python benchmarks/code_tokens.py --before OLD/src/geardyn   # side by side with another tree
"""

from __future__ import annotations

import argparse
import ast
import io
import tokenize
from pathlib import Path

LAYOUT = {
    tokenize.COMMENT,
    tokenize.NL,
    tokenize.NEWLINE,
    tokenize.INDENT,
    tokenize.DEDENT,
    tokenize.ENCODING,
    tokenize.ENDMARKER,
}
DOCUMENTED = (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)


def docstring_starts(source: str) -> set[tuple[int, int]]:
    """Where each docstring of ``source`` starts, as (line, column)."""
    starts = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, DOCUMENTED) and node.body:
            first = node.body[0]
            value = first.value if isinstance(first, ast.Expr) else None
            if isinstance(value, ast.Constant) and isinstance(value.value, str):
                starts.add((first.lineno, first.col_offset))
    return starts


def count(path: Path) -> int:
    """Code tokens of one file."""
    source = path.read_text(encoding="utf-8")
    docs = docstring_starts(source)
    return sum(
        1
        for tok in tokenize.generate_tokens(io.StringIO(source).readline)
        if tok.type not in LAYOUT and not (tok.type == tokenize.STRING and tok.start in docs)
    )


def counts(root: Path) -> dict[str, int]:
    """Code tokens of every ``.py`` file below ``root``, by path relative to it."""
    return {p.relative_to(root).as_posix(): count(p) for p in sorted(root.rglob("*.py"))}


def package(rel: str) -> str:
    """The package a file is counted under: its first folder, or ``(top)``."""
    return rel.split("/")[0] if "/" in rel else "(top)"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", nargs="?", default="src/geardyn", type=Path)
    parser.add_argument("--before", type=Path, help="another tree of the package, counted side by side")
    parser.add_argument("--files", type=int, default=0, help="also list the N largest files")
    args = parser.parse_args()
    after = counts(args.root)
    before = counts(args.before) if args.before else {}
    groups: dict[str, list[int]] = {}
    for rel, n in after.items():
        groups.setdefault(package(rel), [0, 0])[1] += n
    for rel, n in before.items():
        groups.setdefault(package(rel), [0, 0])[0] += n
    width = max(len(g) for g in groups)
    for name, (b, a) in sorted(groups.items(), key=lambda item: -item[1][1]):
        print(f"{name:<{width}} {a:>8,}" + (f" {b:>8,} {a - b:>+8,}" if before else ""))
    total_b, total_a = sum(before.values()), sum(after.values())
    print(f"{'total':<{width}} {total_a:>8,}" + (f" {total_b:>8,} {total_a - total_b:>+8,}" if before else ""))
    for rel, n in sorted(after.items(), key=lambda item: -item[1])[: args.files]:
        print(f"  {n:>7,} {rel}")


if __name__ == "__main__":
    main()
