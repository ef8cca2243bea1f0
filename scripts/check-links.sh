#!/usr/bin/env bash
# Checks every link of a built book (make docs): Debian's linkchecker with its AnchorCheck
# plugin (scripts/linkcheckerrc), the book's own pages only. Usage: check-links.sh BOOK_DIR.
# First shows the check can fail: a small book with a link to a missing page, to a missing
# anchor and to a missing image must each be refused (and passes without them). linkchecker
# drops root to `nobody`, so it reads world-readable copies in a temporary directory.
# Exit 0: every link resolves; 1: a broken link (the report names it), or the self-test passed
# a broken copy.
set -uo pipefail
book=$1
rc_file=$(dirname "$0")/linkcheckerrc
[ -f "$book/index.html" ] || { echo "check-links: $book/index.html: no such file" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT INT TERM
chmod 755 "$tmp"
check() {  # check DIR LOG: linkchecker's exit code over DIR's index.html
  chmod -R a+rX "$1"
  linkchecker -f "$rc_file" --no-status "$1/index.html" > "$2" 2>&1
}
# The self-test runs on a small book of two pages and an image (linkchecker takes about a
# minute and a half over the whole book, and three copies of it cost three of those): the
# clean small book must pass, so each refusal below is the planted fault's.
small() {  # small FAULT: the small book in $tmp/copy, FAULT planted in its index.html
  rm -rf "$tmp/copy" && mkdir -p "$tmp/copy/images"
  cp "$book/$(cd "$book" && ls images/*.png | head -1)" "$tmp/copy/images/real.png"
  printf '<!DOCTYPE html>\n<html><head><title>i</title></head><body><main>%s%s</main></body></html>\n' \
    '<a href="USAGE.html#real-anchor">x</a><img src="images/real.png" alt="x">' "$1" > "$tmp/copy/index.html"
  printf '<!DOCTYPE html>\n<html><head><title>u</title></head><body><main><h2 id="real-anchor">a</h2></main></body></html>\n' \
    > "$tmp/copy/USAGE.html"
}
small ''
check "$tmp/copy" "$tmp/self.log" || { cat "$tmp/self.log"; echo "check-links: self-test: the clean small book failed" >&2; exit 1; }
for fault in '<a href="no-such-page.html">x</a>' '<a href="USAGE.html#no-such-anchor">x</a>' \
             '<img src="images/no-such-image.png" alt="x">'; do
  small "$fault"
  if check "$tmp/copy" "$tmp/self.log"; then
    echo "check-links: self-test: $fault passed the check" >&2; exit 1
  fi
  echo "check-links: self-test: $fault refused"
done
rm -rf "$tmp/copy" && cp -r "$book" "$tmp/copy"
if ! check "$tmp/copy" "$tmp/book.log"; then
  cat "$tmp/book.log"; echo "check-links: broken links in $book" >&2; exit 1
fi
grep -E "links in .* URLs checked" "$tmp/book.log" | sed "s|^|check-links: $book: |"
