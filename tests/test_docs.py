"""The docs hold together: every relative link and #section in README.md, agents/ and docs/ leads
somewhere, and so does every section a code comment cites (a docs page and its section)."""
import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "agents").glob("*.md")), *sorted((ROOT / "docs").rglob("*.md"))]
SOURCES = sorted([*(p for d in ("agents", "robostrich_suite", "tools", "tests") for p in (ROOT / d).rglob("*.py")),
                  ROOT / "robostrich_commands.py"])


def anchor(heading: str) -> str:
    """A Markdown heading's anchor as GitHub makes it: lower case, punctuation dropped, spaces to '-'."""
    text = heading.lstrip("#").strip().lower()
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(page: pathlib.Path) -> set:
    return {anchor(line) for line in page.read_text().splitlines() if line.startswith("#")}


def test_the_anchor_rule():
    assert anchor("## A longer, quieter lesson 3: 71.4 % within 1 cm (2026-12-02)") == \
        "a-longer-quieter-lesson-3-714--within-1-cm-2026-12-02"
    assert anchor("### `ventral_from_base` by budget") == "ventral_from_base-by-budget"


def test_every_link_of_the_docs_leads_somewhere():
    broken = []
    for page in PAGES:
        for link in re.findall(r"\]\(([^)\s]+)\)", page.read_text()):
            if link.startswith(("http://", "https://")):
                continue
            path, _, section = link.partition("#")
            target = (page.parent / path).resolve() if path else page
            if target == page and path:
                broken.append(f"{page.relative_to(ROOT)} links to itself: {link}")
            elif not target.exists():
                broken.append(f"{page.relative_to(ROOT)}: {link} does not exist")
            elif section and target.suffix == ".md" and section not in anchors(target):
                broken.append(f"{page.relative_to(ROOT)}: {link} names no section of {target.name}")
    assert not broken, "\n".join(broken)


def test_every_section_the_code_cites_exists():
    broken = [f"{source.relative_to(ROOT)}: {page}#{section}"
              for source in SOURCES for page, section in re.findall(r"(docs/[\w/]+\.md)#([\w\-]+)", source.read_text())
              if not (ROOT / page).exists() or section not in anchors(ROOT / page)]
    assert not broken, "\n".join(broken)
