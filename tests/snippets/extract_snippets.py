#!/usr/bin/env python3
"""Extracts the C++ snippets of README.md and docs/*.md into apps that build against the installed package.

Every ```cpp block must be preceded (on the line before, blank lines allowed) by one marker saying what it is:
  <!-- snippet: fragment -->  statements (and #include lines, which move to the top of the file) compiled as the body
                              of `void f(btDiscreteDynamicsWorld* world, btRigidBody* a, btRigidBody* b,
                              btBulletWorldImporter* importer)`; the harness (harness.inc) calls it on a fresh world
                              (importer null): b hangs from a on a stock btHingeConstraint the harness allocated, then
                              steps the world and checks the bodies stay finite. A fragment removes what it adds to
                              the world except constraints (the harness deletes every constraint left in it, except
                              an importer's).
  <!-- snippet: fragment-loaded -->  a fragment run that way and also on each .bullet file the app is given, loaded by
                              a btBulletWorldImporter (importer: it; a and b: its first two rigid bodies), which then
                              deletes what it loaded (deleteAllData).
  <!-- snippet: program -->   a whole program with its own main(): built alone, and run (it must return 0).
  <!-- snippet: skip -->      shown, not compiled (say why in the text: pseudo-code, a pattern with placeholders).
A ```cmake block marked <!-- snippet: app-cmake --> (README's quick start) is the CMakeLists.txt every app is built
with, verbatim: what a user pastes is what is tested.

  extract_snippets.py <source dir> <output dir>
writes <output dir>/CMakeLists.txt, <output dir>/fragments/main.cpp (every page's fragments in one app: README's
snippets pasted together must link), <output dir>/program_<page>_<n>/main.cpp, and prints one line per app.
"""
import pathlib
import re
import sys

MARK = re.compile(r'<!--\s*snippet:\s*([a-z-]+)\s*-->')
FENCE = re.compile(r'^```(\S*)\s*$')


def blocks(path):
    """(kind, language, code, line) for every fenced block of a page, kind from the marker before it (or None)."""
    lines = path.read_text(encoding='utf-8').split('\n')
    pending, i = None, 0
    while i < len(lines):
        m = MARK.search(lines[i])
        if m:
            pending = (m.group(1), i + 1)
            i += 1
            continue
        f = FENCE.match(lines[i])
        if f and f.group(1):
            start = i
            i += 1
            body = []
            while i < len(lines) and not lines[i].startswith('```'):
                body.append(lines[i])
                i += 1
            kind = pending[0] if pending and start - pending[1] <= 2 else None
            yield kind, f.group(1), '\n'.join(body), start + 1
            pending = None
        elif lines[i].strip():
            pending = None if not lines[i].strip().startswith('<!--') else pending
        i += 1


def main():
    src, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    pages = [src / 'README.md'] + sorted((src / 'docs').glob('*.md'))
    app_cmake, fragments, programs, errors = None, [], [], []
    for page in pages:
        rel = page.relative_to(src)
        for kind, lang, code, line in blocks(page):
            where = f'{rel}:{line}'
            if lang == 'cmake' and kind == 'app-cmake':
                app_cmake = code
            elif lang in ('cpp', 'c++', 'cxx'):
                if kind in ('fragment', 'fragment-loaded'):
                    fragments.append((where, code, kind == 'fragment-loaded'))
                elif kind == 'program':
                    programs.append((where, code))
                elif kind != 'skip':
                    errors.append(f'{where}: a ```{lang} block without <!-- snippet: fragment|fragment-loaded|program|skip -->')
    if app_cmake is None:
        errors.append('README.md: no ```cmake block marked <!-- snippet: app-cmake -->')
    if errors:
        sys.exit('extract_snippets: ' + '\n'.join(errors))
    out.mkdir(parents=True, exist_ok=True)
    harness = (pathlib.Path(__file__).parent / 'harness.inc').read_text(encoding='utf-8')

    def write_app(name, text):
        d = out / name
        d.mkdir(parents=True, exist_ok=True)
        (d / 'main.cpp').write_text(text, encoding='utf-8')
        (d / 'CMakeLists.txt').write_text(app_cmake + '\n', encoding='utf-8')
        print(name)

    includes, bodies = [], []
    for n, (where, code, _) in enumerate(fragments):
        body = []
        for l in code.split('\n'):
            if l.startswith('#include'):
                inc = l.split('//')[0].strip()
                if inc not in includes:
                    includes.append(inc)
            else:
                body.append('  ' + l if l else '')
        bodies.append(f'// {where}\nstatic void fragment{n}(btDiscreteDynamicsWorld* world, btRigidBody* a, btRigidBody* b,\n'
                      '                          btBulletWorldImporter* importer)\n'
                      '{\n  (void)world; (void)a; (void)b; (void)importer;\n  {  // its own scope: a fragment may name its own variables so\n'
                      + '\n'.join(body) + '\n  }\n}\n')
    table = ',\n'.join(f'    {{"{where}", fragment{n}, {"true" if loaded else "false"}}}'
                        for n, (where, _, loaded) in enumerate(fragments))
    text = ('// Generated by tests/snippets/extract_snippets.py from the docs\' fragments: do not edit.\n' +
            '\n'.join(includes) + '\n#include <btBulletDynamicsCommon.h>\n'
            '#include <BulletWorldImporter/btBulletWorldImporter.h>\n\n' + '\n'.join(bodies) +
            harness.replace('@FRAGMENTS@', table))
    write_app('fragments', text)
    for n, (where, code) in enumerate(programs):
        write_app(f'program{n}', f'// Generated from {where}: do not edit.\n{code}\n')


if __name__ == '__main__':
    main()
