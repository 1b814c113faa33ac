"""A strict, bounded YAML reader for case and sweep files.

PyYAML's safe loader is safe against code execution, not against a hostile or mistaken file.  This reader
adds what a batch tool needs:

* only regular files, at most MAX_BYTES, opened without blocking (a FIFO is refused, not waited on);
* nesting at most MAX_DEPTH deep, and at most MAX_NODES nodes once every alias is expanded (an "alias bomb"
  of nested anchors is refused before anything is built from it);
* duplicate keys refused (YAML would silently keep the last one);
* the YAML 1.2 core schema: 017 is 17 and 1:30 is text (YAML 1.1 reads them as octal 15 and base-60 90),
  yes/no/on/off are text, 1e-8 is a number;
* control characters refused in keys and values, with their path.

Errors are :class:`YamlProblem` with a dotted path (or a line and column) and a one-line message; values are
quoted as short excerpts, so a huge value never makes a huge message.
"""
from __future__ import annotations

import os
import re
import stat
from pathlib import Path
from typing import Any

import yaml

MAX_BYTES = 1_000_000
MAX_DEPTH = 32
MAX_NODES = 50_000
CONTROL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")


class YamlProblem(ValueError):
    """An unreadable or refused YAML document: ``path`` (dotted, or "line L, column C") and ``message``."""

    def __init__(self, path: str, message: str):
        self.path = path
        self.message = message
        super().__init__(f"{path}: {message}" if path else message)


def excerpt(value: Any, width: int = 40) -> str:
    """repr(value), cut to ``width`` characters: error messages quote values, never dump them."""
    if isinstance(value, (list, dict)):
        kind = "list" if isinstance(value, list) else "mapping"
        return f"a {kind} of {len(value)} item{'s' if len(value) != 1 else ''}"
    text = repr(value)
    return text if len(text) <= width else text[:width - 5] + "…" + text[-4:]


def read_text(path: str | Path, what: str = "file", max_bytes: int = MAX_BYTES,
              typical: str = "a case is a few kB") -> str:
    """The text of a regular file of at most ``max_bytes``; OSError/ValueError with a plain message otherwise
    (``typical`` says how large such a file usually is, for the message on an oversize one)."""
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except FileNotFoundError:
        raise FileNotFoundError(f"the {what} does not exist") from None
    except IsADirectoryError:
        raise ValueError(f"expected a {what}, got a directory") from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise ValueError(f"expected a {what}, got a directory")
        if not stat.S_ISREG(st.st_mode):
            raise ValueError(f"expected a regular {what}, got a device, FIFO or socket")
        if st.st_size > max_bytes:
            raise ValueError(f"the {what} is {st.st_size / 1e6:.1f} MB; {typical} (limit {max_bytes / 1e6:g} MB)")
        data = os.read(fd, max_bytes + 1)
    finally:
        os.close(fd)
    if len(data) > max_bytes:
        raise ValueError(f"the {what} is larger than {max_bytes / 1e6:g} MB")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"the {what} is not UTF-8 text (byte {exc.start})") from None


class _Resolver(yaml.resolver.BaseResolver):
    """Implicit tags of the YAML 1.2 core schema."""


_Resolver.add_implicit_resolver("tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"),
                                list("tTfF"))
_Resolver.add_implicit_resolver("tag:yaml.org,2002:int", re.compile(r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$"),
                                list("-+0123456789"))
_Resolver.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"),
    list("-+0123456789."))
_Resolver.add_implicit_resolver("tag:yaml.org,2002:null", re.compile(r"^(?:~|null|Null|NULL|)$"), ["~", "n", "N", ""])


class _Constructor(yaml.constructor.SafeConstructor):
    def construct_yaml_int(self, node):
        text = self.construct_scalar(node)
        if text.startswith("0o"):
            return int(text[2:], 8)
        if text.startswith("0x"):
            return int(text[2:], 16)
        return int(text, 10)

    def construct_yaml_float(self, node):
        text = self.construct_scalar(node).lower()
        if text.endswith(".inf"):
            return float("-inf") if text.startswith("-") else float("inf")
        if text == ".nan":
            return float("nan")
        return float(text)

    def construct_mapping(self, node, deep=False):  # no merge keys (<<): YAML 1.2 has none
        mapping = {}
        for key_node, value_node in node.value:
            key = self.construct_object(key_node, deep=deep)
            try:
                hash(key)
            except TypeError:
                raise YamlProblem(_where(key_node), "a mapping key must be a plain value, not a list or mapping")
            mapping[key] = self.construct_object(value_node, deep=deep)
        return mapping


_Constructor.add_constructor("tag:yaml.org,2002:int", _Constructor.construct_yaml_int)
_Constructor.add_constructor("tag:yaml.org,2002:float", _Constructor.construct_yaml_float)
_Constructor.add_constructor("tag:yaml.org,2002:map", lambda c, n: c.construct_mapping(n))


class _Loader(yaml.reader.Reader, yaml.scanner.Scanner, yaml.parser.Parser, yaml.composer.Composer,
              _Constructor, _Resolver):
    def __init__(self, stream):
        yaml.reader.Reader.__init__(self, stream)
        yaml.scanner.Scanner.__init__(self)
        yaml.parser.Parser.__init__(self)
        yaml.composer.Composer.__init__(self)
        _Constructor.__init__(self)
        _Resolver.__init__(self)


def _where(node) -> str:
    mark = getattr(node, "start_mark", None)
    return f"line {mark.line + 1}, column {mark.column + 1}" if mark else ""


def _flow_depth(text: str) -> int:
    """Deepest nesting of [ and { outside quotes: checked before parsing, whose recursion it would exhaust."""
    depth = deepest = 0
    quote = None
    for ch in text:
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif ch in "]}":
            depth = max(0, depth - 1)
        elif ch == "\n":
            quote = None
    return deepest


def _inspect(node, path: str, depth: int, sizes: dict) -> int:
    """Expanded node count below ``node`` (aliases counted every time they are used); checks keys, depth and
    control characters on the way."""
    if depth > MAX_DEPTH:
        raise YamlProblem(path or _where(node), f"nested more than {MAX_DEPTH} levels deep")
    key = id(node)
    if key in sizes:
        if sizes[key] < 0:
            raise YamlProblem(path or _where(node), "a structure that contains itself (recursive alias)")
        return sizes[key]
    sizes[key] = -1
    total = 1
    if isinstance(node, yaml.ScalarNode):
        if CONTROL.search(node.value):
            raise YamlProblem(path or _where(node), f"contains a control character (at {_where(node)}); "
                                                    f"remove it or write it as an escape")
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            total += _inspect(item, f"{path}[{i}]", depth + 1, sizes)
    elif isinstance(node, yaml.MappingNode):
        seen = {}
        for k, v in node.value:
            name = k.value if isinstance(k, yaml.ScalarNode) else None
            if isinstance(k, yaml.ScalarNode) and CONTROL.search(k.value):
                raise YamlProblem(path or _where(k), f"a key contains a control character (at {_where(k)})")
            if name is not None:
                if name in seen:
                    raise YamlProblem(f"{path}.{name}" if path else str(name),
                                      f"given twice (lines {seen[name]} and {k.start_mark.line + 1}); YAML would "
                                      f"silently keep the last one: merge them")
                seen[name] = k.start_mark.line + 1
            child = f"{path}.{name}" if path else str(name)
            total += _inspect(k, child, depth + 1, sizes) + _inspect(v, child, depth + 1, sizes)
    sizes[key] = total
    if total > MAX_NODES:
        raise YamlProblem(path or _where(node), f"expands to more than {MAX_NODES} values (through aliases "
                                                f"or sheer size); a case has a few dozen")
    return total


def loads(text: str) -> Any:
    """Parse one YAML document strictly (see the module's docstring); raises :class:`YamlProblem`."""
    if len(text) > MAX_BYTES:
        raise YamlProblem("", f"the text is larger than {MAX_BYTES / 1e6:g} MB")
    if _flow_depth(text) > MAX_DEPTH:
        raise YamlProblem("", f"brackets nested more than {MAX_DEPTH} levels deep")
    try:
        loader = _Loader(text)
    except yaml.YAMLError as exc:  # the reader refuses non-printable characters at once
        raise YamlProblem("", f"unreadable text: {str(exc).splitlines()[-1].strip()}") from None
    try:
        try:
            node = loader.get_single_node()
        except yaml.YAMLError as exc:
            mark = getattr(exc, "problem_mark", None)
            where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else ""
            problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
            raise YamlProblem(where, f"YAML syntax error: {problem}") from None
        except RecursionError:
            raise YamlProblem("", f"nested more than {MAX_DEPTH} levels deep") from None
        if node is None:
            return None
        _inspect(node, "", 0, {})
        try:
            return loader.construct_document(node)
        except yaml.YAMLError as exc:
            raise YamlProblem(_where(getattr(exc, "problem_mark", None) and node), str(exc).splitlines()[0]) from None
        except (ValueError, OverflowError) as exc:
            if isinstance(exc, YamlProblem):
                raise
            raise YamlProblem("", f"unreadable value: {exc}") from None
    finally:
        loader.dispose()
