/* What output_stage.c (creating, locking, cleaning up) and output_commit.c (moving a
 * finished run into place) share: the stage itself. Private to src/io/.
 */
#ifndef THZ_IO_OUTPUT_STAGE_INTERNAL_H
#define THZ_IO_OUTPUT_STAGE_INTERNAL_H

#include <stdbool.h>

#include "core/error.h"

/* How a finished run goes into OUTDIR.
 *   STAGE_SWAP:  the stage is a sibling of OUTDIR (same directory, same file system);
 *                the commit exchanges the two directories with one renameat2(2)
 *                RENAME_EXCHANGE, so at every instant OUTDIR is the old run or the new one.
 *   STAGE_FILES: OUTDIR is a mount point or the working directory, which cannot be
 *                swapped (or should not: a shell inside it would be left in a deleted
 *                directory); the stage is inside OUTDIR and the commit renames file by
 *                file, all or nothing on failure but not across a crash. */
typedef enum stage_mode { STAGE_SWAP = 0, STAGE_FILES } stage_mode;

/* A name the run claims (output_stage_claim): one file's, or every file's of a sensor. */
typedef struct stage_claim {
    char *name; /* the file name, or the sensor's stem "S." */
    bool sensor;
} stage_claim;

struct output_stage {
    char *outdir;       /* as given, for messages */
    char *target;       /* OUTDIR without trailing '/', or its real path for "." and ".." */
    char *parent;       /* the directory holding OUTDIR */
    char *prefix;       /* PARENT/.thzmap-<hash of OUTDIR's name>: names of our siblings */
    char *dir;          /* the staging directory */
    char *lock_path;    /* the lock file (removed by output_stage_destroy) */
    int lock_fd;        /* -1: none */
    char *created_root; /* the topmost directory the stage created, or NULL */
    stage_mode mode;
    bool committed;
    stage_claim *claims;
    size_t n_claims;
};

/* Whether OUTDIR's file `name` is claimed by this run: not kept unless the run wrote it. */
bool stage_claimed(const struct output_stage *stage, const char *name);

/* The commit of either mode (output_commit.c). */
thz_status stage_commit_swap(struct output_stage *stage, thz_error *err);
thz_status stage_commit_files(struct output_stage *stage, thz_error *err);

/* Removes dir's regular files and symbolic links, then dir if it is then empty
 * (a directory inside, which thzmap never writes, keeps it). */
void stage_remove_files(const char *dir);

/* Moves every entry of dir that is not a regular file (directories, links: a user's,
 * never thzmap's) into `into`, where no entry of that name exists. */
void stage_move_others(const char *dir, const char *into);

#endif
