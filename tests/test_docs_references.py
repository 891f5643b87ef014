"""Every code reference in the docs resolves (a newcomer reads the docs first).

The docs scanned: ``README.md``, ``docs/*.md`` and every ``.md`` file in the package (its
``FORMAT.md`` files, the dataset card template, the data sources). Only spans in backticks
outside fenced code blocks are read, and only those that are clearly a reference to this
repository:

* **a path** (``render/spectral.py``, ``spectrinsic/scenes/``, ``scripts/x.py``,
  ``tests/...py``): a span of path characters with a ``/`` whose first folder is a folder of the
  repository (so ``eval/REPORT.md`` in a dataset or ``intern/cycles/...`` in Blender are not
  read). It resolves when it names a file or folder relative to the repository root, to
  ``spectrinsic/``, to the doc's own folder, or as the tail of a path in the repository
  (``algebra/modes.py`` in a section about ``render/``). A bare file name ``x.py`` resolves
  when a module of that name exists; a file of another project is named by its project's path
  (``mitsuba/.../prb.py``), whose first folder is not one of ours;
* **a path with a name** (``render/spectral._map_lights``,
  ``gt_export/sample/render_spp.render_spp``): the module resolves as a path, and the name is
  defined in it (below);
* **a dotted module name** (``spectrinsic.scenes.validate_scene``): the longest prefix that is
  a module or package of the repository, then the rest as names in it;
* **module.name** (``mitsuba_bsdfs._tint``): the first word is the name of a module of the
  package (``np.cross`` and ``mi.Ray3f`` are not read); a module's file in backticks followed
  by a name in backticks (``algebra/shares.py` `compose``) is read as ``algebra/shares.compose``;
* **Class.member** (``RenderResult.parts``, ``_Run.plan``): the first word is CapWords (after
  leading underscores), with a member; the class must be defined somewhere in the package and
  hold that member. ``spectrinsic.x`` where no prefix is a module is a namespace (an
  entry-point group, an EXR header attribute), not read.

A name is defined in a module when the module (``ast``, nothing imported) binds it at top
level: ``def``, ``class``, an assignment or an import (a package's ``__init__`` re-exports),
or - one level down - when a class of the module holds it (a method, a field, a class
attribute). ``Class.member`` also accepts a member an instance attribute set in a method
(``self.x = ...``). Trailing calls and subscripts (``.build()``, ``[j]``) are dropped.
Placeholders (``<name>``, ``*``, ``{a,b}``, ``...``) are not read.

Historical names are allowed where the doc says so: a reference in the same sentence as a word
such as *removed*, *renamed*, *gone*, *replaced*, *folded into*, *formerly* or *no longer*
(:data:`HISTORICAL`) names past code on purpose (a sentence may wrap over lines), so does every row of a table
whose introducing paragraph says so (``Removed (one commit per kind):``), and every reference
under a heading that contains *History* or *Changes*. Nothing else is allowlisted.

Also read: ``make X`` (a target of the Makefile); a pytest node id ``tests/x.py::test_y`` (the
file defines the test); ``python [-P] -m spectrinsic.x ...`` and ``python [-P] scripts/x.py ...``
(the module or script exists); and every ``spectrinsic VERB ... --flag`` command line, in
backticks or on a line of a fenced block, whose verb and flags the argument parser must know
(it is built, as ``spectrinsic --help`` builds it; nothing is run).
"""

from __future__ import annotations

import ast
import functools
import re
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "spectrinsic"
#: Folders of the repository that are not its source (build outputs, local data, tools' caches).
SKIPPED_FOLDERS = frozenset({"data", "results", "build", "dist"})
IDENT = r"[A-Za-z_][A-Za-z0-9_]*"
#: A path: path characters with at least one ``/``, optionally a trailing ``/``.
PATH = re.compile(r"[A-Za-z0-9_.\-]+(?:/[A-Za-z0-9_.\-]+)+/?|[A-Za-z0-9_.\-]+/")
#: A path to a module (no ``.py``) followed by one or two names.
PATH_NAME = re.compile(rf"((?:{IDENT}/)+{IDENT})((?:\.{IDENT}){{1,2}})")
#: A bare file name of a module.
PY_FILE = re.compile(rf"{IDENT}\.py")
#: ``a.b`` or ``a.b.c``... of identifiers.
DOTTED = re.compile(rf"{IDENT}(?:\.{IDENT})+")
#: What a reference may end with and still be the same reference: a call or a subscript.
TRAILER = re.compile(r"(?:\([^()]*\)|\[[^\[\]]*\])+$")
#: Words that mark a sentence naming past code on purpose.
HISTORICAL = re.compile(
    r"\b(removed|renamed|gone|replaced|formerly|no longer|deleted|retired|dropped|superseded|"
    r"folded into|used to)\b",
    re.IGNORECASE,
)
HISTORY_HEADING = re.compile(r"^#+ .*\b(history|changes)\b", re.IGNORECASE)
MAKE = re.compile(r"make ([a-z][a-z0-9_-]*)")
#: A command line that runs a module or a script of ours.
COMMAND = re.compile(r"python[0-9.]* ")
#: A pytest node id: a test file and a test in it.
TEST_ID = re.compile(rf"([A-Za-z0-9_./-]+\.py)::((?:{IDENT}::)?{IDENT})")
SPAN = re.compile(r"`([^`\n]+)`")
#: A module's file followed by one of its names: ``algebra/shares.py` `compose``.
FILE_THEN_NAME = re.compile(rf"`((?:[\w.-]+/)*{IDENT})\.py` `({IDENT})(?:\([^`]*\))?`")
FENCE = re.compile(r"^\s*(```|~~~)")


def doc_files() -> list[Path]:
    """The documents whose references are checked."""
    docs = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    return docs + sorted(PACKAGE.rglob("*.md"))


@dataclass(frozen=True)
class Reference:
    """One backticked span of a document: where it is and whether its sentence is historical."""

    doc: Path
    line: int
    text: str
    historical: bool

    def __str__(self) -> str:
        return f"{self.doc.relative_to(ROOT)}:{self.line}: `{self.text}`"


def _sentence_around(line: str, start: int, end: int) -> str:
    """The sentence (or table cell) of ``line`` holding the span ``start:end``."""
    cut = re.compile(r"(?<=[.!?])\s+(?=[A-Z(`*])|\|")
    left = [m.end() for m in cut.finditer(line, 0, start)]
    right = cut.search(line, end)
    return line[left[-1] if left else 0 : right.start() if right else len(line)]


def _is_table(line: str) -> bool:
    return line.lstrip().startswith("|")


def _starts_block(line: str) -> bool:
    """Whether ``line`` starts a new block: a heading, a table row, a list item."""
    return line.startswith("#") or _is_table(line) or bool(re.match(r"\s*([-*+]|\d+\.)\s", line))


@dataclass(frozen=True)
class Block:
    """A paragraph, list item, heading or table row, its lines joined by spaces (a sentence may
    wrap), with the line number and offset in ``text`` where each of its lines starts."""

    text: str
    lines: tuple[tuple[int, int], ...]

    def line_at(self, offset: int) -> int:
        return max(number for number, start in self.lines if start <= offset)


def blocks(doc: Path) -> list[Block]:
    """The blocks of ``doc`` outside fenced code."""
    found: list[list[tuple[int, str]]] = [[]]
    fenced = False
    for number, line in enumerate(doc.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
        elif fenced or not line.strip():
            found.append([])
        elif _starts_block(line) or not found[-1] or _is_table(found[-1][-1][1]):
            found.append([(number, line)])
        else:
            found[-1].append((number, line.strip()))
    joined = []
    for lines in filter(None, found):
        starts = [0]
        for _, line in lines[:-1]:
            starts.append(starts[-1] + len(line) + 1)
        text = " ".join(line for _, line in lines)
        joined.append(Block(text, tuple((n, s) for (n, _), s in zip(lines, starts, strict=True))))
    return joined


def references(doc: Path) -> list[Reference]:
    """Every backticked span of ``doc`` outside fenced code blocks."""
    found: list[Reference] = []
    history = past_table = False
    lead = ""  # the last block of text before a table: it introduces the table
    for block in blocks(doc):
        if block.text.startswith("#"):
            history = bool(HISTORY_HEADING.match(block.text))
        if _is_table(block.text):
            past_table = past_table or bool(HISTORICAL.search(lead))
        else:
            lead, past_table = block.text, False
        for span in SPAN.finditer(block.text):
            past = history or past_table
            past = past or bool(HISTORICAL.search(_sentence_around(block.text, *span.span())))
            line = block.line_at(span.start())
            found.append(Reference(doc, line, span.group(1).strip(), past))
        for pair in FILE_THEN_NAME.finditer(block.text):
            past = history or past_table
            past = past or bool(HISTORICAL.search(_sentence_around(block.text, *pair.span())))
            name = f"{pair.group(1)}.{pair.group(2)}"
            found.append(Reference(doc, block.line_at(pair.start()), name, past))
    return found


@functools.cache
def repo_paths() -> tuple[frozenset[str], frozenset[str]]:
    """Every file and folder of the repository (relative, posix) and every folder name."""
    paths: set[str] = set()
    names: set[str] = set()

    def walk(folder: Path) -> None:
        for entry in folder.iterdir():
            if entry.name.startswith(".") or entry.name == "__pycache__":
                continue
            if folder == ROOT and entry.name in SKIPPED_FOLDERS:
                continue
            if entry.name.endswith(".egg-info"):
                continue
            paths.add(entry.relative_to(ROOT).as_posix())
            if entry.is_dir():
                names.add(entry.name)
                walk(entry)

    walk(ROOT)
    return frozenset(paths), frozenset(names)


@functools.cache
def path_tails() -> dict[str, tuple[str, ...]]:
    """Every tail of every repository path (``modes.py``, ``algebra/modes.py``, ...) -> paths."""
    tails: dict[str, list[str]] = {}
    for path in repo_paths()[0]:
        parts = path.split("/")
        for cut in range(len(parts)):
            tails.setdefault("/".join(parts[cut:]), []).append(path)
    return {tail: tuple(sorted(found)) for tail, found in tails.items()}


def resolve_path(path: str, doc: Path) -> tuple[str, ...]:
    """The repository paths ``path`` names: relative to the root, to ``spectrinsic/`` or to the
    doc's folder, else as the tail of a path."""
    path = path.rstrip("/")
    paths = repo_paths()[0]
    bases = ("", "spectrinsic/", doc.parent.relative_to(ROOT).as_posix() + "/")
    exact = tuple((base + path).lstrip("/") for base in bases if (base + path).lstrip("/") in paths)
    return exact or path_tails().get(path, ())


def is_repo_path(text: str) -> bool:
    """Whether ``text`` is clearly a path into this repository (its first folder is ours)."""
    if not PATH.fullmatch(text) or ".." in text.split("/"):
        return False
    return text.split("/")[0] in repo_paths()[1]


@functools.cache
def module_tree(path: str) -> ast.Module:
    return ast.parse((ROOT / path).read_text(encoding="utf-8"), filename=path)


def _bound(body: list[ast.stmt]) -> dict[str, ast.stmt]:
    """The names a block binds at its own level, with the statement that binds each."""
    bound: dict[str, ast.stmt] = {}
    for node in body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            bound[node.name] = node
        elif isinstance(node, ast.Assign | ast.AnnAssign | ast.AugAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for target in targets:
                for name in ast.walk(target):
                    if isinstance(name, ast.Name):
                        bound[name.id] = node
        elif isinstance(node, ast.Import | ast.ImportFrom):
            for alias in node.names:
                bound[(alias.asname or alias.name).split(".")[0]] = node
        elif isinstance(node, ast.If | ast.Try):
            nested = node.body + node.orelse + getattr(node, "finalbody", [])
            bound.update(_bound(nested))
    return bound


def class_members(node: ast.ClassDef) -> set[str]:
    """What a class holds: its own names and the ``self.x`` attributes its methods set."""
    members = set(_bound(node.body))
    for child in ast.walk(node):
        if isinstance(child, ast.Attribute) and isinstance(child.ctx, ast.Store):
            if isinstance(child.value, ast.Name) and child.value.id == "self":
                members.add(child.attr)
    return members


def defines(module: str, names: list[str]) -> bool:
    """Whether the module file ``module`` defines ``names`` (a name, or a class and its member)."""
    bound = _bound(module_tree(module).body)
    first = bound.get(names[0])
    if len(names) == 1:
        if first is not None:
            return True
        classes = [n for n in bound.values() if isinstance(n, ast.ClassDef)]
        return any(names[0] in class_members(c) for c in classes)
    return isinstance(first, ast.ClassDef) and names[1] in class_members(first)


def modules_at(path: str, doc: Path) -> tuple[str, ...]:
    """The module files of the repository that ``path`` (no ``.py``) names."""
    return resolve_path(path + ".py", doc) + resolve_path(path + "/__init__.py", doc)


@functools.cache
def package_classes() -> dict[str, tuple[ast.ClassDef, ...]]:
    """Every class of the package, by name."""
    classes: dict[str, list[ast.ClassDef]] = {}
    for path in sorted(repo_paths()[0]):
        if path.startswith("spectrinsic/") and path.endswith(".py"):
            for node in ast.walk(module_tree(path)):
                if isinstance(node, ast.ClassDef):
                    classes.setdefault(node.name, []).append(node)
    return {name: tuple(found) for name, found in classes.items()}


#: What :func:`check` says of a reference that resolves (None: the span is not a reference).
RESOLVES = ""


def check(reference: Reference) -> str | None:
    """Why ``reference`` does not resolve; :data:`RESOLVES` when it does; None when the span is
    not a reference to this repository."""
    text = TRAILER.sub("", reference.text)
    if any(mark in text for mark in "<>*{}…") or "..." in text:
        return None
    if make := MAKE.fullmatch(text):
        return RESOLVES if make.group(1) in make_targets() else "no such make target"
    if COMMAND.match(text):
        return _check_command(text.split(), reference.doc)
    if test := TEST_ID.fullmatch(text):
        return _check_test(test.group(1), test.group(2), reference.doc)
    return _check_name(text, reference.doc)


def _check_name(text: str, doc: Path) -> str | None:
    """A path, a path with names, a module file name or a dotted name (see the module docstring)."""
    if is_repo_path(text) and resolve_path(text, doc):
        return RESOLVES
    named = PATH_NAME.fullmatch(text)
    if named and text.rsplit(".", 1)[1] not in FILE_EXTENSIONS | {"py"}:
        module, names = named.group(1), named.group(2)[1:].split(".")
        if is_repo_path(module + "/"):
            return _check_names(modules_at(module, doc), module, names)
    if is_repo_path(text):
        return "no such file or folder"
    if PY_FILE.fullmatch(text):
        return RESOLVES if path_tails().get(text) else "no module of that name"
    if DOTTED.fullmatch(text) and text.rsplit(".", 1)[1] not in FILE_EXTENSIONS:
        return _check_dotted(text.split("."), doc)
    return None


def _check_names(modules: tuple[str, ...], module: str, names: list[str]) -> str:
    if not modules:
        return f"no module {module}"
    if any(defines(found, names[:2]) for found in modules):
        return RESOLVES
    return f"{'.'.join(names)} is not defined in {module}"


def _check_dotted(words: list[str], doc: Path) -> str | None:
    """A dotted name: the longest prefix that is a module of ours, then names in it; else a
    ``Class.member`` of the package; else not ours (``np.cross``)."""
    top = 1 if words[0] == "spectrinsic" else 0
    for cut in range(len(words), top, -1):
        path = "/".join(words[:cut])
        modules = modules_at(path, doc)
        if modules and all(m.startswith(("spectrinsic/", "scripts/")) for m in modules):
            return RESOLVES if cut == len(words) else _check_names(modules, path, words[cut:])
    cap = words[0].lstrip("_")
    if top or not cap or not (cap[0].isupper() and not cap.isupper()):
        return None  # a namespace (an entry-point group, a file attribute) or another project's
    classes = package_classes().get(words[0], ())
    if not classes:
        return f"no class {words[0]} in the package"
    if any(words[1] in class_members(c) for c in classes):
        return RESOLVES
    return f"no class {words[0]} holds {words[1]}"


def _check_test(path: str, name: str, doc: Path) -> str:
    """``tests/x.py::test_y`` (or ``::Class::test_y``): the file exists and defines the test."""
    files = resolve_path(path, doc) if is_repo_path(path) else ()
    if not files:
        return "no such file or folder"
    return _check_names(files, path, name.split("::"))


def _check_command(words: list[str], doc: Path) -> str | None:
    """``python [-P] -m module ...`` or ``python [-P] scripts/x.py ...``: the module or the
    script exists (what follows is its arguments)."""
    script = next((w for w in words[1:] if not w.startswith("-")), "")
    if "-m" in words:
        script = words[words.index("-m") + 1] if words.index("-m") + 1 < len(words) else ""
        if not script.startswith("spectrinsic"):
            return None
        return _check_name(script, doc) or (
            RESOLVES if modules_at(script.replace(".", "/"), doc) else "no such module"
        )
    return _check_name(script, doc) if script.endswith(".py") else None


#: Last words that make a dotted span a file name (``manifest.json``), not a module's name.
FILE_EXTENSIONS = frozenset(
    "json exr png csv md txt npz npy yaml yml xml obj ply mtl spd dng hdr blend gltf glb pt "
    "html js cff toml cpp h stl off jpg pdf ocio".split()
)


@functools.cache
def make_targets() -> frozenset[str]:
    text = (ROOT / "Makefile").read_text(encoding="utf-8")
    return frozenset(re.findall(r"^([a-z][a-z0-9_-]*):", text, re.MULTILINE))


def test_every_code_reference_in_the_docs_resolves() -> None:
    stale = []
    for doc in doc_files():
        for reference in references(doc):
            why = check(reference)
            if why and not reference.historical:
                stale.append(f"{reference}: {why}")
    assert not stale, "stale references in the docs:\n" + "\n".join(stale)


def _checked(text: str) -> str | None:
    return check(Reference(ROOT / "docs" / "example.md", 1, text, historical=False))


def test_the_checker_reports_what_does_not_exist_and_passes_what_does() -> None:
    resolving = [
        "spectrinsic/render/spectral.py",
        "render/base/translate.material_bsdf",
        "gt_export/sample/render_spp.render_spp",
        "algebra/modes.py",
        "spectrinsic.scenes.validate_scene",
        "RenderResult.parts",
        "make lint",
        "tests/test_style.py::test_no_function_body_is_over_sixty_lines",
        "python -P -m spectrinsic.bench --only residual",
        "python -P scripts/mit_stress.py --table",
    ]
    stale = [
        "render/base/translate._glass_bsdf",  # docs/ARCHITECTURE.md once named it
        "spectrinsic/render/spectrum.py",
        "spectrinsic.scenes.validate_scenes",
        "RenderResult.shape",
        "_DiagonalPasses._render",
        "make lints",
        "tests/test_style.py::test_a_test_that_does_not_exist",
        "tests/test_stile.py::test_long_functions_are_found",
        "python -P -m spectrinsic.benches --only residual",
        "python -P scripts/mit_stresses.py",
    ]
    not_ours = ["np.cross", "mi.Ray3f", "eval/REPORT.md", "manifest.json", "<stem>_meshes/"]
    assert [t for t in resolving if _checked(t) != RESOLVES] == []
    assert [t for t in stale if not _checked(t)] == []
    assert [t for t in not_ours if _checked(t) is not None] == []


def test_a_sentence_or_table_saying_removed_names_past_code_on_purpose(tmp_path: Path) -> None:
    doc = tmp_path / "history.md"
    doc.write_text(
        "The passes record `_DiagonalPasses` was\nremoved in issue 46. It reads `RenderResult.parts`.\n\n"
        "Removed (one commit per kind):\n\n| what |\n|---|\n| `RenderResult.shape` |\n\n"
        "Kept:\n\n| what |\n|---|\n| `RenderResult.raw` |\n\n## History\n\n`LightTransport.shape`\n",
        encoding="utf-8",
    )
    found = {r.text: r.historical for r in references(doc)}
    assert found == {
        "_DiagonalPasses": True,
        "RenderResult.parts": False,
        "RenderResult.shape": True,
        "RenderResult.raw": False,
        "LightTransport.shape": True,
    }


#: A command line of ``spectrinsic``: in backticks, or a line of a fenced block (``\`` joins).
SPECTRINSIC_COMMAND = re.compile(r"(?:\$ )?spectrinsic (-|[a-z]+\b)")
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")


def command_lines(doc: Path) -> list[tuple[int, str]]:
    """The ``spectrinsic ...`` command lines of ``doc`` (line number, text; comments cut), from
    backticks outside historical sentences and from fenced blocks."""
    found = [
        (r.line, r.text)
        for r in references(doc)
        if not r.historical and SPECTRINSIC_COMMAND.match(r.text)
    ]
    fenced, held = False, ""
    for number, line in enumerate(doc.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            fenced, held = not fenced, ""
            continue
        text = held + line.split(" #")[0].strip()
        held = text[:-1] + " " if fenced and text.endswith("\\") else ""
        if fenced and not held and SPECTRINSIC_COMMAND.match(text):
            found.append((number, text))
    return found


@dataclass(frozen=True)
class Cli:
    """What the parser takes: each verb's option strings (``""``: the options before the verb)
    and the options before the verb that take a value (``--data-dir DIR``)."""

    flags: dict[str, frozenset[str]]
    valued: frozenset[str]


def parsed_cli() -> Cli:
    import argparse

    from spectrinsic.cli import build_parser

    parser = build_parser()
    flags = {"": frozenset(parser._option_string_actions)}
    valued = frozenset(
        option
        for action in parser._actions
        if action.nargs is None and action.option_strings
        for option in action.option_strings
    )
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for verb, sub in action.choices.items():
                flags[verb] = frozenset(sub._option_string_actions)
    return Cli(flags, valued)


def command_problems(text: str, cli: Cli) -> list[str]:
    """What the parser would refuse in the command line ``text``: its verb, its flags."""
    if any(mark in text for mark in "{}<>"):
        return []  # a placeholder for several verbs or values
    words, verb = iter(text.removeprefix("$ ").split()[1:]), ""
    for word in words:
        if not word.startswith("-"):
            verb = word
            break
        if word in cli.valued:
            next(words, None)
    if verb in ("...", "…"):
        return []  # any verb
    if verb not in cli.flags:
        return [f"no verb {verb}"]
    known = cli.flags[verb]
    return [f"{verb or 'spectrinsic'} has no {f}" for f in FLAG.findall(text) if f not in known]


def test_every_command_line_in_the_docs_names_a_verb_and_flags_that_exist() -> None:
    cli = parsed_cli()
    good = [
        "spectrinsic check --noise DIR",
        "spectrinsic --debug render x.xml --out o",
        "spectrinsic --data-dir render dataset --out o",  # a data folder called render
        "spectrinsic --version",
    ]
    bad = ["spectrinsic check --noisy DIR", "spectrinsic rendre x.xml", "spectrinsic --nope"]
    assert [t for t in good if command_problems(t, cli)] == []
    assert [t for t in bad if not command_problems(t, cli)] == []
    wrong = []
    for doc in doc_files():
        for number, text in command_lines(doc):
            where = f"{doc.relative_to(ROOT)}:{number}: `{text}`"
            wrong += [f"{where}: {why}" for why in command_problems(text, cli)]
    assert not wrong, "command lines in the docs that the parser refuses:\n" + "\n".join(wrong)
