# Where the calibration's goals pull against each other (docs/calibration.md, "Why no point meets
# both goals").
#
# Reads the study replicates of one or more finished calibration sweeps (mmh sweep with
# configs/sweeps/calibrate_people.json or a next_round.json: cells/<id>/out/replicates.csv, and
# results.csv for each cell's six parameters) and tabulates, over bins of the viewers' judgement
# noise sigma and the learning rate ell (the two parameters that move the conflicting numbers),
# the share of simulated studies that
#   - reach the paper's 18 of 20 b_i above chance (h2_above_chance >= 18): the paper's count lies
#     inside the central 90 % only where this share is about 0.05 or more (its quantile counts
#     ties half);
#   - reach the paper's "no take-order effect" (H3 mixed model p >= 0.05) and its normal H3
#     residuals (Shapiro-Wilk p >= 0.05): the conclusions goal wants both in >= 80 %;
# with the bins' mean H1 m, H2 b and Friedman chi-squared beside them. The other four parameters
# vary over their priors inside each bin, as in the sweeps.
#
# Usage: Rscript calibrate/goal_conflicts.R SWEEP_DIR [SWEEP_DIR ...]
# Cost: about 2 s for two 300-cell sweeps (reading 600 small CSVs).
args <- commandArgs(trailingOnly = TRUE)
if (length(args) == 0) stop("usage: Rscript calibrate/goal_conflicts.R SWEEP_DIR [SWEEP_DIR ...]")

parameter_columns <- c(sigma = "viewer.judgement_noise", w_a = "viewer.artefact_weight",
                       ell = "population.learning_mean", h = "population.move_threshold_mean",
                       pi = "self_appraisal.progress_weight", c = "self_appraisal.choice_bonus")

read_sweep <- function(dir) {
  cells <- read.csv(file.path(dir, "results.csv"), check.names = FALSE)
  missing <- setdiff(c("cell", parameter_columns), names(cells))
  if (length(missing) > 0)
    stop(dir, "/results.csv: no column ", paste(missing, collapse = ", "),
         " (expected a calibration sweep over the six people parameters)")
  rows <- lapply(seq_len(nrow(cells)), function(i) {
    file <- file.path(dir, "cells", cells$cell[i], "out", "replicates.csv")
    if (!file.exists(file)) return(NULL)
    r <- read.csv(file)
    for (p in names(parameter_columns)) r[[p]] <- cells[[parameter_columns[[p]]]][i]
    r
  })
  do.call(rbind, rows)
}

d <- do.call(rbind, lapply(args, read_sweep))
d$above_chance_18 <- d$h2_above_chance >= 18
d$h3_no_effect <- d$p_h3_mixed_model >= 0.05
d$h3_residuals_normal <- d$p_h3_residual_normality >= 0.05
d$sigma_bin <- cut(d$sigma, c(0, 0.15, 0.2, 0.25, 0.4))
d$ell_bin <- cut(d$ell, c(-0.001, 0.03, 0.06, 0.1, 0.3))

cat(sprintf("%d simulated studies from %d sweep(s)\n\n", nrow(d), length(args)))
table <- aggregate(cbind(above_chance_18, h3_no_effect, h3_residuals_normal, h1_mean_m, h2_mean_b,
                         friedman_chi_squared) ~ sigma_bin + ell_bin, d, mean)
table$studies <- aggregate(h1_mean_m ~ sigma_bin + ell_bin, d, length)$h1_mean_m
table[, 3:8] <- round(table[, 3:8], 3)
table$all_three <- table$above_chance_18 >= 0.05 & table$h3_no_effect >= 0.8 &
  table$h3_residuals_normal >= 0.8
print(table, row.names = FALSE)

# The same three shares' dependence on all six parameters at once (logistic regressions on the
# parameters scaled to their priors' ranges: the coefficient is the change in log-odds across the
# whole prior), so that the two-parameter table is not mistaken for the whole story.
prior_low <- c(sigma = 0.02, w_a = 0.005, ell = 0, h = 0, pi = 0, c = 0)
prior_high <- c(sigma = 0.4, w_a = 0.05, ell = 0.3, h = 3, pi = 0.4, c = 0.3)
for (p in names(prior_low)) d[[p]] <- (d[[p]] - prior_low[[p]]) / (prior_high[[p]] - prior_low[[p]])
cat("\nlog-odds change across each parameter's prior range (z in brackets):\n")
for (outcome in c("above_chance_18", "h3_no_effect", "h3_residuals_normal")) {
  fit <- glm(as.formula(paste(outcome, "~ sigma + w_a + ell + h + pi + c")), family = binomial,
             data = d)
  s <- summary(fit)$coefficients[-1, , drop = FALSE]
  cat(sprintf("  %-20s %s\n", outcome,
              paste(sprintf("%s %+.2f (%.0f)", rownames(s), s[, 1], s[, 3]), collapse = "  ")))
}
