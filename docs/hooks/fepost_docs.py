"""MkDocs hooks of the fepost documentation.

* ``on_config``: pages named in ``mkdocs.yml``'s nav whose file is not in
  ``docs/`` are dropped from the nav (with an info line), so pages written
  later land by adding their file.
* ``on_page_markdown``: the marker ``<!-- fepost:cli-reference -->`` is replaced
  by the command-line reference generated from ``fepost.cli.build_parser()``:
  every subcommand registered there appears, with its usage, description,
  arguments, defaults and choices.
"""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

log = logging.getLogger("mkdocs.hooks.fepost")

CLI_MARKER = "<!-- fepost:cli-reference -->"


def _prune(items, docs: Path):
    kept = []
    for item in items:
        if isinstance(item, dict):
            (title, value), = item.items()
            if isinstance(value, list):
                sub = _prune(value, docs)
                if sub:
                    kept.append({title: sub})
                continue
            if isinstance(value, str) and not value.startswith(("http://", "https://")):
                if not (docs / value).is_file():
                    log.info("fepost docs: %s (%s) not written yet: left out of the nav", value, title)
                    continue
            kept.append(item)
        elif isinstance(item, str) and not (docs / item).is_file():
            log.info("fepost docs: %s not written yet: left out of the nav", item)
        else:
            kept.append(item)
    return kept


def on_config(config, **kwargs):
    if config.get("nav"):
        config["nav"] = _prune(config["nav"], Path(config["docs_dir"]))
    return config


def _escape(text: str) -> str:
    return text.replace("|", "\\|").replace("<", "&lt;").replace(">", "&gt;")


def _help(action: argparse.Action) -> str:
    text = action.help or ""
    if text == argparse.SUPPRESS:
        return ""
    params = {k: v for k, v in vars(action).items() if not k.startswith("_")}
    if isinstance(params.get("choices"), (list, tuple)):
        params["choices"] = ", ".join(map(str, params["choices"]))
    try:
        text = text % params
    except (KeyError, TypeError, ValueError):
        text = text.replace("%%", "%")
    return " ".join(text.split())


def _names(action: argparse.Action) -> str:
    if action.option_strings:
        meta = ""
        if action.nargs != 0:
            meta = " " + (action.metavar or action.dest.upper())
        return ", ".join(f"`{o}{meta}`" for o in action.option_strings)
    return f"`{action.metavar or action.dest}`"


def _details(action: argparse.Action) -> str:
    bits = []
    if action.required and action.option_strings:
        bits.append("required")
    if action.choices:
        bits.append("one of " + ", ".join(f"`{c}`" for c in action.choices))
    default = action.default
    if action.option_strings and action.nargs != 0 and default not in (None, argparse.SUPPRESS):
        bits.append(f"default `{default}`")
    return "; ".join(bits)


def _table(actions) -> list[str]:
    rows = ["| argument | meaning | |", "|---|---|---|"]
    for a in actions:
        if isinstance(a, argparse._HelpAction) or a.help == argparse.SUPPRESS:
            continue
        rows.append(f"| {_names(a)} | {_escape(_help(a))} | {_escape(_details(a))} |")
    return rows if len(rows) > 2 else []


def _usage(parser: argparse.ArgumentParser) -> str:
    formatter = argparse.HelpFormatter(prog=parser.prog, width=100)
    formatter.add_usage(parser.usage, parser._actions, parser._mutually_exclusive_groups, prefix="")
    return formatter.format_help().strip()


def cli_reference() -> str:
    """Markdown reference of every fepost subcommand, from the argparse parser."""
    from fepost.cli import build_parser

    parser = build_parser()
    lines = ["```text", f"{_usage(parser)}", "```", ""]
    lines += [" ".join((parser.description or "").split()), ""]
    lines += _table([a for a in parser._actions if not isinstance(a, argparse._SubParsersAction)])
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    helps = {c.dest: c.help for a in subs for c in a._choices_actions}
    for sub in subs:
        for name, p in sub.choices.items():
            lines += ["", f"## fepost {name}", ""]
            if helps.get(name):
                lines += [f"*{_escape(helps[name])}*", ""]
            lines += ["```text", _usage(p), "```", ""]
            if p.description:
                lines += [_escape(" ".join(p.description.split())), ""]
            for group in p._action_groups:
                rows = _table(group._group_actions)
                if not rows:
                    continue
                title = group.title or "arguments"
                lines += [f"**{title}**", "", *rows, ""]
    return "\n".join(lines) + "\n"


def on_page_markdown(markdown: str, page, config, files, **kwargs):
    if CLI_MARKER in markdown:
        markdown = markdown.replace(CLI_MARKER, cli_reference())
    return markdown
