#!/usr/bin/env python3
"""Prints FILE:LINE: NAME: N lines for every function definition longer than --max lines.

A function's length is counted as clang-tidy's readability-function-size counts it: the lines from
its opening brace to its closing brace, whitespace and comments included. Definitions are found in
the text (comments, strings and character literals removed first): a brace block whose header holds
a parameter list and is not a namespace, class, struct, union, enum or initialiser, at namespace scope
or in a class body; lambdas and blocks inside a function count toward it. Exit status 1 when any
function is too long, else 0.
"""
import argparse
import re
import sys

_TOKEN = re.compile(r'//[^\n]*|/\*.*?\*/|R"([^(\s]*)\((?:.|\n)*?\)\1"|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'',
                    re.S)
_NOT_FUNCTION = re.compile(r'^\s*(?:template\s*<.*>\s*)?(?:namespace|class|struct|union|enum|extern\s+"C")\b', re.S)


def blank(text):
    """Text with comments and literals replaced by spaces, newlines kept (line numbers stay)."""
    return _TOKEN.sub(lambda m: re.sub(r'[^\n]', ' ', m.group(0)), text)


def functions(text):
    """(line of the opening brace, header, body lines) of every function definition."""
    code = blank(text)
    out = []
    stack = []  # per open brace: (kind, line, header)
    header_start = 0
    line = 1
    for i, c in enumerate(code):
        if c == '\n':
            line += 1
        elif c == '{':
            header = code[header_start:i]
            in_function = any(kind == 'function' for kind, _, _ in stack)
            if in_function:
                kind = 'block'
            elif _NOT_FUNCTION.match(header) or '(' not in header or re.search(r'=\s*$', header):
                kind = 'scope'
            else:
                kind = 'function'
            stack.append((kind, line, header))
            header_start = i + 1
        elif c == '}':
            if stack:
                kind, start, header = stack.pop()
                if kind == 'function':
                    out.append((start, ' '.join(header.split()), line - start + 1))
            header_start = i + 1
        elif c == ';' and not any(kind == 'function' for kind, _, _ in stack):
            header_start = i + 1
    return out


def name_of(header):
    m = re.search(r'([~\w:<>]+)\s*\((?!.*\()', header.split('(')[0] + '(') if '(' in header else None
    names = re.findall(r'([~\w:]+)\s*\(', header)
    return names[0] if names else header[:40]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--max', type=int, default=80)
    parser.add_argument('files', nargs='+')
    args = parser.parse_args()
    long = []
    for path in args.files:
        with open(path, encoding='utf-8') as f:
            text = f.read()
        for start, header, n in functions(text):
            if n > args.max:
                long.append(f'{path}:{start}: {name_of(header)}: {n} lines')
    for entry in long:
        print(entry)
    return 1 if long else 0


if __name__ == '__main__':
    sys.exit(main())
