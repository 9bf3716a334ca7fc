"""Every function the public header declares follows its naming rule (softdeca.h, convention
9): softdeca_<noun>_<verb>[_<what>] with the noun a handle or list and the verb one of the
rule's, constructors _create and _load, struct defaults <struct>_init, handle-less calls
starting with their verb, and four library-wide queries by name. A name outside the rule, a
handle without _destroy or without a constructor fails here."""

from __future__ import annotations

import re
from pathlib import Path

HEADER = (
    Path(__file__).resolve().parents[2]
    / "plugin"
    / "include"
    / "softdeca"
    / "softdeca.h"
)

LIBRARY_QUERIES = {"softdeca_abi_version", "softdeca_version", "softdeca_last_error",
                   "softdeca_status_name"}  # fmt: skip
LISTS = ("blendshape",)
VERBS = (
    "create", "load", "destroy", "get", "set", "find", "evaluate", "prepare", "calibrate",
    "reset", "save", "seek", "advance", "write", "start", "stop", "request", "solve", "step",
)  # fmt: skip
FREE_VERBS = ("convert", "export", "embed", "compute")
CONSTRUCTORS = {"create", "load", "load_memory"}


def declared_functions(text: str) -> list[str]:
    return re.findall(r"SOFTDECA_API\s+[\w\s\*]*?\b(softdeca_\w+)\s*\(", text)


def handles(text: str) -> list[str]:
    """The opaque handle types: `typedef struct softdeca_X softdeca_X;`."""
    return re.findall(r"typedef struct softdeca_(\w+) softdeca_\1;", text)


def init_structs(text: str) -> set[str]:
    """Structs set up by the caller (they start with struct_size)."""
    return set(
        re.findall(r"typedef struct softdeca_(\w+) \{\s*uint32_t struct_size;", text)
    )


def problems_of(text: str) -> list[str]:
    functions = declared_functions(text)
    nouns = sorted(
        handles(text) + list(LISTS), key=len, reverse=True
    )  # avatar_fit first
    structs = init_structs(text)
    problems, constructors = [], {}
    for f in functions:
        name = f.removeprefix("softdeca_")
        if f in LIBRARY_QUERIES or name.split("_")[0] in FREE_VERBS:
            continue
        if name.endswith("_init"):
            if name.removesuffix("_init") not in structs:
                problems.append(f"{f}: _init of no struct that starts with struct_size")
            continue
        noun = next((n for n in nouns if name.startswith(n + "_")), None)
        if noun is None:
            problems.append(f"{f}: starts with no handle or list ({', '.join(nouns)})")
            continue
        rest = name.removeprefix(noun + "_")
        verb = rest.split("_")[0]
        if verb not in VERBS:
            problems.append(f"{f}: '{verb}' is not one of the rule's verbs")
        if verb in ("create", "load") and rest not in CONSTRUCTORS:
            problems.append(f"{f}: a constructor is _create, _load or _load_memory")
        if rest in CONSTRUCTORS:
            constructors.setdefault(noun, []).append(rest)
        if verb in ("get", "set", "find") and rest == verb:
            problems.append(f"{f}: _{verb} names what it reads or changes")
    for noun in handles(text):
        if f"softdeca_{noun}_destroy" not in functions:
            problems.append(
                f"softdeca_{noun}: a handle without softdeca_{noun}_destroy"
            )
        if not constructors.get(noun):
            problems.append(f"softdeca_{noun}: a handle no _create or _load makes")
    return problems


def test_every_declared_function_follows_the_naming_rule() -> None:
    text = HEADER.read_text(encoding="utf-8")
    assert len(declared_functions(text)) > 80
    assert problems_of(text) == []


def test_the_rule_catches_the_names_it_forbids() -> None:
    """The check fails on each kind of name the rule replaced."""
    base = (
        "typedef struct softdeca_player softdeca_player;\n"
        "typedef struct softdeca_sim_settings {\n  uint32_t struct_size;\n} softdeca_sim_settings;\n"
        "SOFTDECA_API softdeca_status softdeca_player_load(const char* path);\n"
        "SOFTDECA_API void softdeca_player_destroy(softdeca_player* p);\n"
    )
    assert problems_of(base) == []
    for bad, says in (
        ("softdeca_player_info", "'info' is not one of the rule's verbs"),
        ("softdeca_player_create_from", "a constructor is"),
        ("softdeca_sim_default_settings", "starts with no handle"),
        ("softdeca_sim_options_init", "_init of no struct"),
        ("softdeca_parameter_find", "starts with no handle"),
        ("softdeca_player_get", "_get names what it reads"),
    ):
        text = base + f"SOFTDECA_API softdeca_status {bad}(void);\n"
        assert any(says in p for p in problems_of(text)), (bad, problems_of(text))
    no_destroy = base.replace("softdeca_player_destroy", "softdeca_player_close")
    assert any("without softdeca_player_destroy" in p for p in problems_of(no_destroy))
    opened = base.replace("softdeca_player_load", "softdeca_player_open")
    assert any("no _create or _load makes" in p for p in problems_of(opened))
