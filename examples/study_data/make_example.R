#!/usr/bin/env Rscript
# Writes the example study data of this folder (docs/statistics.md describes the files):
# 20 animators (A01..A20) rank their 3 takes and montage; 42 scorers (the 20 animators and
# S21..S42) make 420 binary comparisons, 7 per take, 10 per scorer, never of their own
# animation (the paper's design); segment_costs.csv gives the montage cost without and with the
# Segment Length Constraint. The numbers are invented for the example (a made-up preference for
# the montage of about 0.65), not the paper's data.
#
#   Rscript examples/study_data/make_example.R [OUTPUT_DIR]
args <- commandArgs(trailingOnly = TRUE)
out <- if (length(args)) args[1] else {
  file_arg <- grep("^--file=", commandArgs(FALSE), value = TRUE)
  dirname(normalizePath(sub("^--file=", "", file_arg[1])))
}
set.seed(2014)
n <- 20
animators <- sprintf("A%02d", 1:n)
scorers <- c(animators, sprintf("S%02d", 21:42))

# Rankings: the montage tends to come first.
rankings <- do.call(rbind, lapply(animators, function(a) {
  score <- c(take1 = rnorm(1), take2 = rnorm(1), take3 = rnorm(1), montage = rnorm(1, 1.5))
  data.frame(animator = a, item = names(score), rank = rank(-score))
}))

# Comparisons: every (animator, take) shown to 7 scorers, every scorer 10 comparisons, no scorer
# compares their own animation or the same animator twice; drawn until such an assignment exists.
cells <- expand.grid(take = 1:3, animator = animators, stringsAsFactors = FALSE)
assign_scorers <- function() {
  load <- setNames(rep(0, length(scorers)), scorers)
  rows <- list()
  for (i in sample(nrow(cells))) {
    a <- cells$animator[i]
    taken <- vapply(rows, function(r) if (r$animator == a) r$scorer else "", "")
    free <- scorers[load < 10 & scorers != a & !(scorers %in% taken)]
    if (length(free) < 7) return(NULL)
    pick <- free[order(load[free] + runif(length(free)))][1:7]
    load[pick] <- load[pick] + 1
    for (s in pick) rows[[length(rows) + 1]] <- list(scorer = s, animator = a, take = cells$take[i])
  }
  do.call(rbind, lapply(rows, as.data.frame))
}
repeat {
  comparisons <- assign_scorers()
  if (!is.null(comparisons)) break
}
quality <- setNames(rnorm(n, 0, 0.5), animators)
p <- plogis(0.6 + quality[comparisons$animator] + c(0.1, 0, -0.1)[comparisons$take])
comparisons$montage_preferred <- rbinom(nrow(comparisons), 1, p)
comparisons <- comparisons[order(comparisons$scorer, comparisons$animator, comparisons$take), ]

# Segment Length Constraint: half the montages had short segments without it, costing < 1 %.
short <- rep(c(0, 1), length.out = n) * rpois(n, 2) + rep(c(0, 1), length.out = n)
unconstrained <- round(runif(n, 800, 1500), 3)
constrained <- round(unconstrained * (1 + ifelse(short > 0, runif(n, 0.0005, 0.009), 0)), 3)
segment_costs <- data.frame(animator = animators, cost_unconstrained = unconstrained,
                            cost_constrained = constrained, short_segments_unconstrained = short)

write.csv(rankings, file.path(out, "rankings.csv"), row.names = FALSE, quote = FALSE)
write.csv(comparisons, file.path(out, "comparisons.csv"), row.names = FALSE, quote = FALSE)
write.csv(segment_costs, file.path(out, "segment_costs.csv"), row.names = FALSE, quote = FALSE)
