#!/usr/bin/env Rscript
# Compares simulated studies written by `mmh study --out DIR` (e.g. the same config at full and at
# fast fidelity, docs/study.md "Fast against full fidelity"): per study the means over animators of
# animators.csv (artefacts per minute and appeal of each take and the montage, the montage's latent
# quality) and the main statistics of results.json.
#
#   Rscript study/compare_studies.R FULL_DIR FAST_DIR [MORE_DIRS...]
library(jsonlite)

`%||%` <- function(a, b) if (is.null(a)) b else a

summarise_study <- function(dir) {
  a <- read.csv(file.path(dir, "animators.csv"))
  r <- fromJSON(file.path(dir, "results.json"))
  an <- r$analysis
  takes <- sort(as.integer(sub("take([0-9]+)_quality", "\\1",
                                grep("^take[0-9]+_quality$", names(a), value = TRUE))))
  artefacts <- sapply(takes, function(k) a[[sprintf("take%d_artefacts_per_minute", k)]])
  appeal <- sapply(takes, function(k) a[[sprintf("take%d_appeal", k)]])
  fmt <- function(x) paste(formatC(x, digits = 3, format = "g"), collapse = ", ")
  data.frame(
    study = dir,
    animators = nrow(a),
    flips = r$measured_error_model$flip_episodes %||% NA,
    take_artefacts_per_min = fmt(colMeans(artefacts)),
    sd_take_artefacts = signif(sd(as.vector(artefacts)), 3),
    montage_artefacts_per_min = signif(mean(a$montage_artefacts_per_minute), 3),
    montage_quality = signif(mean(a$montage_quality), 3),
    take_appeal = fmt(colMeans(appeal)),
    montage_appeal = signif(mean(a$montage_appeal), 3),
    h1_mean_m = signif(an$h1$mean_m, 3),
    h1_sd_m = signif(an$h1$sd_m, 3),
    montage_wins = an$h1$montage_preferred,
    comparisons = an$h1$comparisons,
    friedman = signif(an$rankings$friedman$statistic %||% NA, 3),
    h3_f = signif(an$h3$mixed_model$take_test$f %||% NA, 3),
    check.names = FALSE)
}

dirs <- commandArgs(TRUE)
if (length(dirs) == 0) stop("usage: Rscript study/compare_studies.R DIR [DIR...]")
out <- do.call(rbind, lapply(dirs, summarise_study))
print(t(out), quote = FALSE)
