#!/usr/bin/env bash
# The repository's Markdown pages as a user's checkout has them: every relative link
# ([text](path), [text](path#anchor), [text](#anchor), images too) names a file of the
# repository, and an anchor names a heading of that page (GitHub's slugs) or an
# <a id=...>; and no page points into ../shared (the team's reference, which a user's
# checkout does not have). scene-format.md's contents line named a heading that was gone
# would pass every other test.
# argv: path to the thzmap binary (unused), repository directory.
. "$(dirname "$0")/lib.sh"

cd "$REPO" || fail "no repository at $REPO"
# the tracked pages; outside a git checkout (an unpacked archive), every page but npm's
{ git ls-files '*.md' 2>/dev/null || find . -name '*.md' -not -path '*/node_modules/*' |
    sed 's|^\./||'; } | grep -v -e '^web/node_modules/' > "$work/pages"
[ "$(wc -l < "$work/pages")" -ge 10 ] || fail "fewer than 10 Markdown pages found: $(cat "$work/pages")"

/usr/bin/python3 - "$work/pages" > "$work/bad" <<'PY'
import os, re, sys

pages = [p.strip() for p in open(sys.argv[1]) if p.strip()]
LINK = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")
ANCHOR = re.compile(r"<a\s+(?:id|name)=\"([^\"]+)\"")


def slug(text):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to '-'."""
    text = re.sub(r"`|\*\*|__", "", text)
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)  # a link: its text
    text = text.strip().lower()
    text = "".join(ch for ch in text if ch.isalnum() or ch in " -_")
    return text.replace(" ", "-")


def anchors(path, cache={}):
    if path not in cache:
        found, seen, fence = set(), {}, False
        for line in open(path, encoding="utf-8"):
            if line.lstrip().startswith("```"):
                fence = not fence
                continue
            found.update(ANCHOR.findall(line))
            m = HEADING.match(line)
            if m and not fence:
                s = slug(m.group(2))
                k = seen.get(s, 0)
                seen[s] = k + 1
                found.add(s if k == 0 else f"{s}-{k}")
        cache[path] = found
    return cache[path]


def prose(text):
    """The page with fenced blocks and code spans blanked (newlines kept): no links."""
    out, fence = [], False
    for line in text.split("\n"):
        if line.lstrip().startswith("```"):
            fence = not fence
            out.append("")
        else:
            out.append("" if fence else line)
    return re.sub(r"`[^`\n]*`", lambda m: " " * len(m.group(0)), "\n".join(out))


bad = links = 0
for page in pages:
    text = open(page, encoding="utf-8").read()
    for n, line in enumerate(text.split("\n"), 1):
        if "../shared" in line or "/work/shared" in line:
            print(f"{page}:{n}: points into ../shared, which a user's checkout lacks")
            bad += 1
    body = prose(text)
    for m in LINK.finditer(body):  # a link's text may run over lines
        target, n = m.group(1), body.count("\n", 0, m.start(1)) + 1
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, mailto:, ...
            continue
        links += 1
        file, _, anchor = target.partition("#")
        dest = os.path.normpath(os.path.join(os.path.dirname(page), file)) if file else page
        if file and not os.path.exists(dest):
            print(f"{page}:{n}: links to {target}: no such file")
            bad += 1
        elif anchor and dest.endswith(".md") and anchor not in anchors(dest):
            print(f"{page}:{n}: links to {target}: {dest} has no heading with that anchor")
            bad += 1
if links < 100:  # the pages hold about 140: fewer means the pattern broke
    print(f"only {links} relative links found")
    bad += 1
print(f"{links} relative links", file=sys.stderr)
sys.exit(1 if bad else 0)
PY
status=$?
[ $status -eq 0 ] || fail "the Markdown pages' links:
$(cat "$work/bad")"
finish "doc links: all checks passed"
