#!/usr/bin/env bash
# Checks every link of a built book (make docs): Debian's linkchecker with its AnchorCheck
# plugin (scripts/linkcheckerrc), the book's own pages only. Usage: check-links.sh BOOK_DIR.
# First shows the check can fail: copies of the book with a link to a missing page, to a
# missing anchor and to a missing image must each be refused. linkchecker drops root to
# `nobody`, so it reads world-readable copies in a temporary directory.
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
for fault in '<a href="no-such-page.html">x</a>' '<a href="USAGE.html#no-such-anchor">x</a>' \
             '<img src="images/no-such-image.png" alt="x">'; do
  rm -rf "$tmp/copy" && cp -r "$book" "$tmp/copy"
  sed -i "s|</main>|$fault</main>|" "$tmp/copy/index.html"
  grep -qF "$fault" "$tmp/copy/index.html" || { echo "check-links: could not plant $fault" >&2; exit 1; }
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
