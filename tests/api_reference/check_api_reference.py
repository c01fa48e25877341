#!/usr/bin/env python3
"""The API reference lists every public symbol: the CTest test api_reference (registered where doxygen is found).

  check_api_reference.py <source dir> <build dir> [cmake]
builds the docs target (doxygen, warnings are errors: any warning fails here too), then reads the public headers
plugin/include/quathinge/*.h with its own parser, independent of doxygen, and checks against doxygen's XML
(<build>/docs/xml) that
- every header is a documented file (its \\file block: without one doxygen drops the file's free functions, enums,
  typedefs, constants and macros from the reference and from its search);
- every public symbol it declares has a documented entry in the right place, with as many entries as the header has
  declarations of that name (overloads): free functions, variables, typedefs, enums and their enumerators, macros
  (include guards aside), classes and structs, and their public members (private sections are left out);
- every file-scope symbol is in the HTML search index;
- the main page includes demos/hello/hello.cpp whole, and links every manual page (README.md, CHANGELOG.md,
  docs/*.md), each copied beside the reference.
Prints what it checked; exits 1 with the list of what is missing.
"""
import pathlib
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

TOKEN = re.compile(r'[A-Za-z_]\w*|\d[\w.]*|::|\S')


def strip_comments_and_literals(text):
    """The code with comments, string and character literals blanked (newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith('//', i):
            j = text.find('\n', i)
            i = n if j < 0 else j
        elif text.startswith('/*', i):
            j = text.find('*/', i + 2)
            j = n if j < 0 else j + 2
            out.append('\n' * text.count('\n', i, j))
            i = j
        elif c in '"\'':
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == '\\' else 1
            out.append(c + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return ''.join(out)


def split_preprocessor(code):
    """(code without preprocessor lines, macros defined other than the include guard)."""
    lines, macros, guard = [], [], None
    for line in code.split('\n'):
        s = line.strip()
        if s.startswith('#'):
            m = re.match(r'#\s*ifndef\s+(\w+)', s)
            if m and guard is None:
                guard = m.group(1)
            m = re.match(r'#\s*define\s+(\w+)', s)
            if m and m.group(1) != guard:
                macros.append(m.group(1))
            lines.append('')
        else:
            lines.append(line)
    return '\n'.join(lines), macros


def matching(tokens, i, open_, close):
    """Index just past the bracket that closes tokens[i] (== open_)."""
    depth = 0
    while i < len(tokens):
        depth += (tokens[i] == open_) - (tokens[i] == close)
        i += 1
        if depth == 0:
            return i
    sys.exit('check_api_reference: unbalanced ' + open_)


def top_level(stmt):
    """The statement's tokens outside any (), [], <> or {} nesting."""
    out, depth = [], 0
    for t in stmt:
        if t in '([{':
            depth += 1
        elif t in ')]}':
            depth -= 1
        elif depth == 0:
            out.append(t)
    return out


def ident(t):
    return re.match(r'[A-Za-z_]\w*$', t) is not None


def declared_names(stmt):
    """[(kind, name)] declared by one statement ending in ';' (or a function definition's head)."""
    while stmt[:2] == ['[', '[']:  # a leading attribute ([[deprecated("...")]], [[nodiscard]]): not a name
        depth, k = 0, 0
        for k, t in enumerate(stmt):
            depth += (t == '[') - (t == ']')
            if depth == 0:
                break
        stmt = stmt[k + 1:]
    if not stmt or stmt[0] in ('friend', 'using', 'static_assert'):
        return []
    if stmt[0] == 'typedef':
        if '(' in stmt and stmt[stmt.index('(') + 1] == '*':  # typedef R (*name)(args)
            return [('typedef', stmt[stmt.index('(') + 2])]
        return [('typedef', [t for t in stmt if ident(t)][-1])]
    if stmt[0] in ('class', 'struct') and '{' not in stmt:
        return []  # a forward declaration
    depth, equals = 0, None
    for k, t in enumerate(stmt):  # the first '=' outside brackets: a variable's initializer or '= delete/0/default'
        depth += (t in '([{<') - (t in ')]}>')
        if t == '=' and depth == 0:
            equals = k
            break
    if 'operator' in stmt:  # operator=, operator(): doxygen's name is the keyword and the symbol, unspaced
        k = stmt.index('operator')
        end = stmt.index('(', k + 2 if stmt[k + 1] == '(' else k + 1)
        return [('function', ''.join(stmt[k:end]))]
    if '(' in stmt[:equals]:  # a function (deleted ones too: doxygen lists them)
        k = stmt.index('(')
        name = stmt[k - 1]
        return [('function', ('~' + name) if k >= 2 and stmt[k - 2] == '~' else name)] if ident(name) else []
    names, declarator = [], []
    for t in stmt + [',']:  # variables: each declarator's name (before '=', '[' or ',')
        if t == ',' and declarator:
            top = top_level(declarator)
            cut = top.index('=') if '=' in top else len(top)
            idents = [x for x in top[:cut] if ident(x)]
            if idents:
                names.append(('variable', idents[-1]))
            declarator = []
        else:
            declarator.append(t)
    return names


def parse_scope(tokens, i, path, public, symbols):
    """Reads declarations up to the closing '}' (or the end); appends (scope path, kind, name) of the public ones."""
    stmt = []
    while i < len(tokens):
        t = tokens[i]
        if t == '}':
            return i + 1
        if t in ('public', 'private', 'protected') and i + 1 < len(tokens) and tokens[i + 1] == ':' and not stmt:
            public = t == 'public'
            i += 2
            continue
        if t == '{':
            head = top_level(stmt)
            if 'enum' in head:
                name = [x for x in head[head.index('enum') + 1:] if ident(x) and x not in ('class', 'struct')][0]
                end = matching(tokens, i, '{', '}')
                body, values = tokens[i + 1:end - 1], []
                for part in ' '.join(body).split(','):
                    if part.strip():
                        values.append(part.split()[0])
                if public:
                    symbols.append((path, 'enum', name))
                    symbols += [(path, 'enumvalue', v) for v in values]
                i, stmt = end, ['enum']  # up to the ';'
                continue
            if 'namespace' in head:
                i = matching(tokens, i, '{', '}')  # nothing public is declared in a namespace here
                stmt = []
                continue
            if stmt and stmt[0] in ('class', 'struct'):
                colon = stmt.index(':') if ':' in stmt else len(stmt)
                name = [x for x in stmt[:colon] if ident(x) and not x.endswith('_API')][-1]
                if public:
                    symbols.append((path, 'class', name))
                i = parse_scope(tokens, i + 1, path + [name], stmt[0] == 'struct', symbols if public else [])
                stmt = ['class']  # up to the ';'
                continue
            if '=' in top_level(stmt):  # a brace initializer: part of the statement
                end = matching(tokens, i, '{', '}')
                stmt += tokens[i:end]
                i = end
                continue
            # a function definition: its head declares it
            if public:
                symbols += [(path, k, n) for k, n in declared_names(stmt)]
            i = matching(tokens, i, '{', '}')
            stmt = []
            continue
        if t == ';':
            if public and stmt not in (['enum'], ['class']):
                symbols += [(path, k, n) for k, n in declared_names(stmt)]
            stmt = []
            i += 1
            continue
        stmt.append(t)
        i += 1
    return i


def header_symbols(header):
    """[(scope path, kind, name)] of the public symbols a header declares."""
    code, macros = split_preprocessor(strip_comments_and_literals(header.read_text(encoding='utf-8')))
    tokens = ' '.join(TOKEN.findall(code))
    # Bullet's macros (Doxyfile PREDEFINED): ATTRIBUTE_ALIGNED16(class) is the class key, BT_DECLARE_ALIGNED_ALLOCATOR();
    # declares operator new and delete
    tokens = tokens.replace('ATTRIBUTE_ALIGNED16 ( class )', 'class').replace('BT_DECLARE_ALIGNED_ALLOCATOR ( ) ;', '')
    tokens = tokens.split()
    symbols = [([], 'define', m) for m in macros]
    parse_scope(tokens, 0, [], True, symbols)
    return symbols


def documented(element):
    """Whether an XML memberdef/enumvalue/compounddef has a brief or detailed description."""
    return any(''.join(element.find(tag).itertext()).strip() for tag in ('briefdescription', 'detaileddescription')
               if element.find(tag) is not None)


def main():
    src, build = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    cmake = sys.argv[3] if len(sys.argv) > 3 else 'cmake'
    docs = subprocess.run([cmake, '--build', str(build), '--target', 'docs'], capture_output=True, text=True)
    if docs.returncode != 0:
        sys.exit('check_api_reference: the docs target failed (a doxygen warning is an error):\n' + docs.stdout[-3000:] +
                 docs.stderr[-3000:])
    xml_dir, html = build / 'docs' / 'xml', build / 'docs' / 'html'
    compounds = {}  # (kind, name) -> compounddef
    for c in ET.parse(xml_dir / 'index.xml').getroot().findall('compound'):
        d = ET.parse(xml_dir / (c.get('refid') + '.xml')).getroot().find('compounddef')
        compounds[('file' if c.get('kind') == 'file' else 'class', d.find('compoundname').text)] = d
    search = ''.join(p.read_text(encoding='utf-8') for p in (html / 'search').glob('*.js'))
    missing, counted = [], {}
    headers = sorted((src / 'plugin' / 'include' / 'quathinge').glob('*.h'))
    for header in headers:
        rel = f'quathinge/{header.name}'
        fdef = compounds.get(('file', header.name))
        if fdef is None or not documented(fdef):
            missing.append(f'{rel}: no documented file (a /** \\file */ block)')
            continue
        wanted = {}
        for path, kind, name in header_symbols(header):
            wanted.setdefault(('::'.join(path), kind, name), 0)
            wanted[('::'.join(path), kind, name)] += 1
        for (scope, kind, name), count in wanted.items():
            counted[kind] = counted.get(kind, 0) + count
            where = f'{rel}: {kind} {scope + "::" if scope else ""}{name}'
            if kind == 'class':
                cdef = compounds.get(('class', f'{scope}::{name}' if scope else name))
                if cdef is None or not documented(cdef):
                    missing.append(f'{where}: no documented class page')
                continue
            owner = fdef if not scope else compounds.get(('class', scope))
            if owner is None:
                missing.append(f'{where}: its class has no page')
                continue
            xml_kind = {'enumvalue': 'enum', 'variable': 'variable', 'function': 'function', 'typedef': 'typedef',
                        'enum': 'enum', 'define': 'define'}[kind]
            entries = []
            for m in owner.iter('memberdef'):
                if m.get('kind') != xml_kind:
                    continue
                if kind == 'enumvalue':
                    entries += [v for v in m.findall('enumvalue') if v.find('name').text == name]
                elif m.find('name').text == name:
                    entries.append(m)
            if not entries:
                missing.append(f'{where}: not in the reference')
            elif kind == 'function' and len(entries) != count:
                missing.append(f'{where}: {count} declarations, {len(entries)} in the reference')
            elif not all(documented(e) for e in entries):
                missing.append(f'{where}: listed without documentation')
            elif not scope and f'"{name}"' not in search and f"'{name}'" not in search and f'>{name}<' not in search:
                missing.append(f'{where}: not in the search index')
    # the main page: the hello-world program whole, and the manual
    page = ET.parse(xml_dir / 'indexpage.xml').getroot()
    hello = src / 'demos' / 'hello' / 'hello.cpp'
    listings = [p for p in page.iter('programlisting') if (p.get('filename') or '').endswith('demos/hello/hello.cpp')]
    hello_lines = hello.read_text(encoding='utf-8').rstrip('\n').count('\n') + 1 if hello.exists() else -1
    if len(listings) != 1 or len(listings[0].findall('codeline')) != hello_lines:
        missing.append(f'main page: demos/hello/hello.cpp ({hello_lines} lines) not included whole')
    index = (html / 'index.html').read_text(encoding='utf-8')
    manual = ['README.md', 'CHANGELOG.md'] + [f'docs/{p.name}' for p in sorted((src / 'docs').glob('*.md'))]
    for page_name in manual:
        if f'href="{page_name}"' not in index:
            missing.append(f'main page: no link to the manual page {page_name}')
        elif not (html / page_name).is_file():
            missing.append(f'main page: {page_name} is linked but not copied beside the reference')
    print('check_api_reference: ' + ', '.join(f'{n} {k}' for k, n in sorted(counted.items())) +
          f' in {len(headers)} headers; main page: hello.cpp ({hello_lines} lines), {len(manual)} manual pages')
    if missing:
        sys.exit('check_api_reference: missing from the API reference:\n  ' + '\n  '.join(missing))
    print('check_api_reference: every public symbol is documented in the reference and its search')


if __name__ == '__main__':
    main()
