#!/usr/bin/env bash
# Exports gsplat's source at its 1.6.0 release commit, with the glm headers its CUDA code
# includes, into .parity-peer/gsplat/ (git-ignored) for scripts/peers/run.sh. Run it on a
# machine with git and network access (or local git copies), from the repository root:
#   bash scripts/peers/fetch-gsplat.sh [DEST]            # DEST: .parity-peer/gsplat
# GSPLAT_GIT and GLM_GIT name where the sources come from: a local git directory (a clone,
# its .git folder, or a bare mirror) or a URL (default: the GitHub repositories; only the
# one commit is fetched). GSPLAT_COMMIT overrides the commit. Nothing else is needed: no
# build, no pip. Writes DEST/PEER_COMMIT and prints DEST's size.
set -euo pipefail

# The mirror has no v1.6.0 tag: c3d59bb is the merge "Update v1.6.0 and bump version"
# (2026-08-14) that set gsplat/version.py to 1.6.0, the release commit of 1.6.0.
GSPLAT_COMMIT=${GSPLAT_COMMIT:-c3d59bbb54f91d1c93f1a80dc86960c696b4a059}
GSPLAT_GIT=${GSPLAT_GIT:-https://github.com/nerfstudio-project/gsplat}
GLM_GIT=${GLM_GIT:-https://github.com/g-truc/glm}
dest=${1:-.parity-peer/gsplat}
# The submodule path that gsplat's JIT builds put on the include path (gsplat/cuda/build.py,
# gsplat/experimental/render/kernels/cuda/build.py).
glm_path=gsplat/cuda/csrc/third_party/glm

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# Prints a git directory holding COMMIT: SOURCE itself when it is a local git directory,
# else a temporary repository with COMMIT fetched from the URL SOURCE.
git_dir_with() {
    local source=$1 commit=$2 name=$3
    if [[ -d $source/.git ]]; then
        source=$source/.git
    fi
    if [[ -d $source ]]; then
        if ! git --git-dir="$source" cat-file -e "$commit^{commit}" 2>/dev/null; then
            echo "fetch-gsplat: $source has no commit $commit" >&2
            return 1
        fi
        echo "$source"
        return 0
    fi
    local dir=$tmp/$name.git
    git init -q --bare "$dir"
    # GitHub serves single commits by id; --depth 1 keeps the download to one tree.
    git --git-dir="$dir" fetch -q --depth 1 "$source" "$commit"
    echo "$dir"
}

gsplat_git=$(git_dir_with "$GSPLAT_GIT" "$GSPLAT_COMMIT" gsplat)
version=$(git --git-dir="$gsplat_git" show "$GSPLAT_COMMIT:gsplat/version.py" |
    sed -n 's/^__version__ = "\(.*\)"/\1/p')
glm_commit=$(git --git-dir="$gsplat_git" ls-tree "$GSPLAT_COMMIT" "$glm_path" | awk '$2 == "commit" {print $3}')
if [[ -z $glm_commit ]]; then
    echo "fetch-gsplat: $GSPLAT_COMMIT has no submodule at $glm_path" >&2
    exit 1
fi
glm_git=$(git_dir_with "$GLM_GIT" "$glm_commit" glm)

rm -rf "$dest"
mkdir -p "$dest/$glm_path"
# The Python package with its CUDA/C++ sources (JIT-built where it runs) and the licence;
# not the docs, examples or tests. (A mirror missing unrelated large blobs, e.g. the docs'
# GIFs, may print "invalid object" for them; the archive of these paths is still whole.)
git --git-dir="$gsplat_git" archive "$GSPLAT_COMMIT" gsplat LICENSE | tar -x -C "$dest"
# glm is header-only: its glm/ folder and its licence.
git --git-dir="$glm_git" archive "$glm_commit" glm copying.txt | tar -x -C "$dest/$glm_path"

if [[ ! -f $dest/$glm_path/glm/glm.hpp || ! -f $dest/gsplat/experimental/render/kernels/cuda/build.py ]]; then
    echo "fetch-gsplat: the export in $dest is incomplete" >&2
    exit 1
fi
echo "nerfstudio-project/gsplat $GSPLAT_COMMIT (version $version); glm $glm_commit" \
    > "$dest/PEER_COMMIT"
echo "fetch-gsplat: gsplat $version at $GSPLAT_COMMIT, glm $glm_commit -> $dest"
echo "fetch-gsplat: $(du -sh "$dest" | cut -f1) in $(find "$dest" -type f | wc -l) files"
