"""CityEngine imports: forwarding and protecting attributes, overriding rules, workspace paths, encodings,
and the confinement of what an import may read."""

import os
import shutil
from pathlib import Path

import pytest

from grammarc.compiler import compile_grammar
from grammarc.diagnostics import render_all
from grammarc.errors import GrammarError
from grammarc.frontend.imports import MAX_GRAMMAR_BYTES, find_roots
from grammarc.ir.printer import print_rule

VERSION = 'version "2019.0"\n'
WORKSPACE = Path(__file__).parent / "grammars" / "cityengine" / "workspace"
TOWN = WORKSPACE / "Town" / "rules" / "main.cga"
KIT = Path(__file__).resolve().parents[2].parent / "shared" / "prt"

#: An imported file: an attribute, a rule that calls another of its rules, and that rule.
STRUCTURE = VERSION + ('attr height = 5\nattr tone = "#ff0000"\n'
                       "Lot --> extrude(height) comp(f) { side : Facade | top : Roof. }\n"
                       "Facade --> color(tone) Wall.\n")


def write(folder: Path, name: str, text: str | bytes) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text, encoding="utf-8")
    return path


def compiled(tmp_path, main: str, start="Lot", **files):
    for name, text in files.items():
        write(tmp_path, name.replace("__", "/"), text)
    return compile_grammar(write(tmp_path, "main.cga", VERSION + main), start=start)


def attrs(grammar) -> dict:
    from grammarc.ir.printer import print_expr
    return {a.name: print_expr(a.default) for a in grammar.module.attrs}


def rules(grammar) -> dict:
    return {r.symbol: print_rule(r) for r in grammar.module.rules}


def errors(tmp_path, main: str, **files) -> list[tuple[str, str]]:
    with pytest.raises(GrammarError) as caught:
        compiled(tmp_path, main, **files)
    return [(d.code, d.message) for d in caught.value.diagnostics if d.is_error]


# ------------------------------------------------------------------------------------------- attributes


def test_attributes_of_the_importing_file_are_forwarded_unless_protected(tmp_path):
    grammar = compiled(tmp_path, 'import a : "st.cga"\nimport b : "st.cga" (height)\nimport c : "st.cga" ()\n'
                       'attr height = 10\nattr tone = "#00ff00"\nLot --> a.Lot b.Lot c.Lot\n', **{"st.cga": STRUCTURE})
    assert attrs(grammar) == {"height": "10", "tone": '"#00ff00"', "b.height": "5", "c.height": "5",
                              "c.tone": '"#ff0000"'}
    assert rules(grammar)["a.Lot"] == "a.Lot ~> extrude(@height) comp(f){ side: a.Facade | top: a.Roof. } : 1"
    assert rules(grammar)["b.Facade"] == "b.Facade ~> color(@tone) b.Wall. : 1"


def test_the_same_file_imported_twice_keeps_two_sets_of_attribute_values(tmp_path):
    grammar = compiled(tmp_path, 'import tall : "st.cga" (height = 20)\nimport low : "st.cga" (height = base / 2)\n'
                       "attr base = 6\nLot --> tall.Lot low.Lot\n", **{"st.cga": STRUCTURE})
    # a value is an expression of the importing file: `base` is its attribute
    assert attrs(grammar) == {"base": "6", "tall.height": "20", "tall.tone": '"#ff0000"',
                              "low.height": "(@base / 2)", "low.tone": '"#ff0000"'}
    assert rules(grammar)["low.Lot"].startswith("low.Lot ~> extrude(@low.height)")


def test_a_value_for_an_attribute_the_file_lacks_is_a_warning(tmp_path):
    grammar = compiled(tmp_path, 'import s : "st.cga" (width = 3)\nLot --> s.Lot\n', **{"st.cga": STRUCTURE})
    assert [(w.code, w.message) for w in grammar.warnings if w.code == "import"] == [
        ("import", "`st.cga` declares no attribute `width`: its value is not used")]


# ------------------------------------------------------------------------------------------------ rules


def test_a_rule_of_the_importing_file_overrides_the_imported_one_where_the_import_calls_it(tmp_path):
    grammar = compiled(tmp_path, 'import st : "st.cga"\nLot --> st.Lot\nst.Facade --> color("#0000ff") st.Facade.\n',
                       **{"st.cga": STRUCTURE})
    printed = rules(grammar)
    assert printed["st.Facade"] == 'st.Facade ~> color("#0000ff") st.Facade. : 1'
    assert "comp(f){ side: st.Facade |" in printed["st.Lot"]
    assert list(printed).count("st.Facade") == 1


def test_an_extension_redefined_in_the_import(tmp_path):
    grammar = compiled(tmp_path, "import e : \"ext.cga\" ( Roof(angle) --> s('1, '1, angle) Flat. )\n"
                       "Lot --> e.Init\n",
                       **{"ext.cga": VERSION + "Init --> extrude(3) Roof(2)\nRoof(angle) --> s('1, angle, '1) R.\n"})
    assert rules(grammar)["e.Roof"] == "e.Roof(angle) ~> S(1r, 1r, $angle) Flat. : 1"
    assert grammar.module.start == "Lot"  # a redefined extension is never the file's first rule


def test_unquoted_and_unprefixed_imports_and_nested_imports(tmp_path):
    grammar = compiled(tmp_path, "import parts : Parts_01.cga\nimport \"sub/base.cga\"\nLot --> parts.Part Base\n",
                       **{"Parts_01.cga": VERSION + 'import inner : "sub/base.cga"\nPart --> inner.Base\n',
                          "sub__base.cga": VERSION + "attr w = 2\nBase --> s(w, 1, 1) Box.\n"})
    printed = rules(grammar)
    assert printed["parts.Part"] == "parts.Part ~> parts.inner.Base : 1"
    assert printed["parts.inner.Base"] == "parts.inner.Base ~> S(@parts.inner.w, 1, 1) parts.inner.Box. : 1"
    assert printed["Base"] == "Base ~> S(@w, 1, 1) Box. : 1"


def test_a_prefixed_leaf(tmp_path):
    grammar = compiled(tmp_path, 'import st : "st.cga"\nLot --> st.Lot st.Facade.\n', **{"st.cga": STRUCTURE})
    assert rules(grammar)["Lot"] == "Lot ~> st.Lot st.Facade. : 1"


# ------------------------------------------------------------------------------------------- functions

#: An imported file of functions: one calls another and reads an attribute and a constant of the file.
UTILITIES = VERSION + ("attr base = 2\nconst factor = 3\n"
                       "twice(x) = x * 2 + base\nscaled = factor * twice(1)\n"
                       'size(x) = case x > 1 : "big" else : "small"\n')


def test_functions_and_constants_of_an_imported_file_are_called_through_its_prefix(tmp_path):
    grammar = compiled(tmp_path, 'import u : "util.cga"\nattr h = u.twice(4) + u.scaled\nattr kind = u.size(h)\n'
                       "Lot --> extrude(u.twice(h)) s(u.factor, '1, '1) X.\n",
                       **{"util.cga": UTILITIES})
    # the body is inlined in the imported file's scope: its attributes and constants under the prefix
    assert attrs(grammar) == {"h": "((8 + @u.base) + (@u.factor * (2 + @u.base)))",
                              "kind": '((@h > 1) ? "big" : "small")', "u.base": "2", "u.factor": "3"}
    assert rules(grammar)["Lot"] == "Lot ~> extrude(((@h * 2) + @u.base)) S(@u.factor, 1r, 1r) X. : 1"


def test_an_imported_function_reads_the_importing_files_attribute_unless_protected(tmp_path):
    grammar = compiled(tmp_path, 'import a : "util.cga"\nimport b : "util.cga" (base)\nattr base = 10\n'
                       "Lot --> s(a.twice(1), b.twice(1), 1) X.\n", **{"util.cga": UTILITIES})
    assert rules(grammar)["Lot"] == "Lot ~> S((2 + @base), (2 + @b.base), 1) X. : 1"


def test_functions_of_unprefixed_and_nested_imports(tmp_path):
    grammar = compiled(tmp_path, 'import "util.cga"\nimport o : "outer.cga"\n'
                       "twice(x) = x\nLot --> s(twice(5), scaled, o.u.twice(o.half(6))) X.\n",
                       **{"util.cga": UTILITIES,
                          "outer.cga": VERSION + 'import u : "util.cga"\nhalf(x) = u.twice(x) / 2\n'})
    # the file's own `twice` wins over the unprefixed import's
    assert rules(grammar)["Lot"] == ("Lot ~> S(5, (@factor * (2 + @base)), ((((12 + @o.u.base) / 2) * 2) "
                                     "+ @o.u.base)) X. : 1")


def test_an_unknown_function_of_an_imported_file(tmp_path):
    [(code, message)] = errors(tmp_path, 'import u : "util.cga"\nLot --> s(u.thrice(1), 1, 1) X.\n',
                               **{"util.cga": UTILITIES})
    assert (code, message) == ("unknown-function", "unknown function `u.thrice` (did you mean `u.twice`?)")


def test_calls_through_the_prefix_of_an_import_that_failed_are_not_reported_again(tmp_path):
    [(code, message)] = errors(tmp_path, 'import u : "gone.cga"\nLot --> s(u.twice(1), u.half, 1) X.\n')
    assert (code, message) == ("import", f"cannot import: `gone.cga` is not found in {tmp_path}")


# ---------------------------------------------------------------------------------------- the workspace


def test_the_town_of_the_miniature_workspace():
    """Imports across projects by workspace paths, twice with different values, a rule of the town
    overriding the house's, a Windows-1252 file (warned once), a file with a BOM, and assets found by
    project-absolute and project-relative paths and from an imported file's project: one asset per file."""
    grammar = compile_grammar(TOWN)
    assert [w.message for w in grammar.warnings if w.code == "encoding"] == [
        "`/ESRI.lib/rules/facade.cga` is not UTF-8: read as Windows-1252 (save it as UTF-8 to silence this)"]
    assert attrs(grammar)["tall.height"] == "12" and attrs(grammar)["low.height"] == "4"
    assert attrs(grammar)["low.roofColor"] == "@townRoof"
    assert rules(grammar)["tall.Roof"].startswith("tall.Roof ~> color(@roofColor) Door")
    assert rules(grammar)["low.Roof"] == "low.Roof ~> color(@low.roofColor) low.Chimney : 1"
    assert grammar.assets == ("builtin:cube", "builtin:quad", "assets/door.obj", "chimney.obj",
                              "Houses/assets/window.obj")
    assert not [w for w in grammar.warnings if w.code == "asset"]


def test_a_workspace_given_to_a_grammar_outside_it(tmp_path):
    main = write(tmp_path, "main.cga", VERSION + 'import h : "/Houses/rules/house.cga"\nLot --> h.Lot\n')
    with pytest.raises(GrammarError, match="is in no CityEngine workspace"):
        compile_grammar(main)
    grammar = compile_grammar(main, workspace=WORKSPACE)
    assert "h.facade.Window" in rules(grammar)
    assert find_roots(main, WORKSPACE).workspaces == (WORKSPACE.resolve(),)


def test_a_cityengine_project_finds_its_assets(tmp_path):
    project = tmp_path / "ws" / "Proj"
    shutil.copytree(WORKSPACE / "Houses", project)
    roots = find_roots(project / "rules" / "house.cga")
    assert (roots.project, roots.workspaces) == (project.resolve(), (project.parent.resolve(),))
    assert roots.asset_roots()[:3] == (project / "rules", project.resolve() / "assets", project.resolve())


@pytest.mark.skipif(not (KIT / "rpk" / "candler.rpk").is_file(), reason="PRT kit (../shared/prt) absent")
def test_candler_in_its_project_builds_as_its_package(tmp_path):
    """The .cga in a CityEngine project finds the assets its package holds: same terminals, same faces."""
    py7zr = pytest.importorskip("py7zr")
    from grammarc.build import BuildOptions, build

    project = tmp_path / "Tutorial"
    with py7zr.SevenZipFile(KIT / "rpk" / "candler.rpk") as archive:
        archive.extractall(project)
    (project / ".resolvemap.xml").unlink()  # a project, not a package
    counts = []
    for grammar in (project / "rules" / "Candler Building.cga", KIT / "rpk" / "candler.rpk"):
        result = build(grammar, tmp_path / "c.npz", options=BuildOptions(start="Footprint"))
        counts.append((result.derived, result.counts.get("mesh_faces", 0), result.grammar.assets))
    assert counts[0] == counts[1] and counts[0][1] > 900


# -------------------------------------------------------------------------------------------- encodings


def test_an_imported_file_in_windows_1252_is_read_with_a_warning(tmp_path):
    """Today's reader crashed: `'UnicodeDecodeError' object has no attribute 'strerror'`."""
    grammar = compiled(tmp_path, 'import f : "f.cga"\nLot --> f.Lot\n',
                       **{"f.cga": VERSION.encode() + "// façade\nLot --> extrude(2) Mass.\n".encode("cp1252")})
    [warning] = [w for w in grammar.warnings if w.code == "encoding"]
    assert "`" + str(tmp_path / "f.cga") + "` is not UTF-8" in warning.message


def test_error_positions_in_a_windows_1252_file_stay_file_line_col(tmp_path):
    with pytest.raises(GrammarError) as caught:
        compiled(tmp_path, 'import f : "f.cga"\nLot --> f.Lot\n',
                 **{"f.cga": VERSION.encode() + "// é\nLot --> extrude(2 Mass.\n".encode("cp1252")})
    [error] = [d for d in caught.value.diagnostics if d.is_error]
    assert (error.span.file, error.span.line) == (str(tmp_path / "f.cga"), 3)


# ------------------------------------------------------------------------------------------ confinement


@pytest.mark.parametrize("path, fragment", [
    ("/proc/self/environ", "is not a CGA rule file"),
    ("/dev/zero", "is not a CGA rule file"),
    ("/etc/secret.cga", "is in no CityEngine workspace"),
    ("../outside.cga", "leaves the grammar's folders"),
    ("C:/rules/x.cga", "is a path of the host"),
])
def test_imports_outside_the_roots_are_refused(tmp_path, path, fragment):
    write(tmp_path, "outside.cga", VERSION + "Lot --> X.\n")
    found = errors(tmp_path / "g", f'import x : "{path}"\nLot --> x.Lot\n')
    assert len(found) == 1 and found[0][0] == "import" and fragment in found[0][1], found


def test_an_absolute_host_path_is_not_a_workspace_path(tmp_path):
    outside = write(tmp_path, "outside.cga", VERSION + "Lot --> X.\n")
    [(code, message)] = errors(tmp_path / "g", f'import x : "{outside}"\nLot --> x.Lot\n')
    assert code == "import" and "is in no CityEngine workspace" in message


def test_links_out_of_the_roots_and_devices_are_refused(tmp_path):
    (tmp_path / "g").mkdir()
    os.symlink("/dev/zero", tmp_path / "g" / "zero.cga")
    os.symlink(write(tmp_path, "outside.cga", VERSION + "Lot --> X.\n"), tmp_path / "g" / "out.cga")
    found = errors(tmp_path / "g", 'import z : "zero.cga"\nimport o : "out.cga"\nLot --> z.Lot o.Lot\n')
    assert [code for code, _ in found] == ["import", "import"]


def test_a_file_over_the_size_limit_is_refused_after_limit_plus_one_bytes(tmp_path):
    big = tmp_path / "big.cga"
    with big.open("wb") as handle:  # sparse: no 16 MiB written
        handle.truncate(MAX_GRAMMAR_BYTES + 10)
    [(code, message)] = errors(tmp_path, 'import b : "big.cga"\nLot --> b.Lot\n')
    assert code == "import" and "larger than 16 MiB" in message


def test_an_error_never_quotes_a_file_that_is_not_a_grammar(tmp_path):
    write(tmp_path, "secret.cga", b"TOKEN=hunter2\0\0binary")
    with pytest.raises(GrammarError) as caught:
        compiled(tmp_path, 'import s : "secret.cga"\nLot --> s.Lot\n')
    shown = render_all(list(caught.value.diagnostics), caught.value.sources)
    assert "not a text file" in shown and "hunter2" not in shown


def test_imports_inside_a_rule_package_stay_inside_it(tmp_path):
    py7zr = pytest.importorskip("py7zr")
    from grammarc.build import BuildOptions, grammar_source

    write(tmp_path, "host.cga", VERSION + "Lot --> X.\n")
    package = tmp_path / "evil.rpk"
    with py7zr.SevenZipFile(package, "w") as archive:
        archive.writestr(VERSION + f'import a : "{tmp_path / "host.cga"}"\nimport b : "../../host.cga"\n'
                         "import c : \"/proc/self/environ\"\n@StartRule\nLot --> a.Lot b.Lot c.Lot\n", "rules/m.cga")
    with grammar_source(package, BuildOptions()) as (source, display, options), \
            pytest.raises(GrammarError) as caught:
        compile_grammar(source, display=display, asset_roots=options.asset_roots, workspace=options.workspace)
    assert [d.code for d in caught.value.diagnostics if d.is_error] == ["import"] * 3


def test_the_record_of_a_project_build_finds_its_assets_again(tmp_path):
    """The record's meta names the project's folders: a later render loads the assets it inserted."""
    from grammarc.build import build
    from grammarc.io.npz import read_instances
    from grammarc.model.assets import asset_library

    build(TOWN, tmp_path / "town.npz")
    record = read_instances(tmp_path / "town.npz")
    library = asset_library(list(record["assets"]), record)
    assert [library[i].n_polygons for i in range(2, 5)] == [2, 4, 1]  # door, chimney, window
