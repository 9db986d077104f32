#!/usr/bin/env Rscript
# The whole `mmh stats` analysis done by R from the CSV files (docs/statistics.md), as the oracle
# of tests/study/study_analysis_test.cc:
#
#   Rscript tests/data/study/analyze_study.R STUDY_DIR OUTPUT.json
#
# rankings.csv -> friedman.test; comparisons.csv -> m_ij, H1 (t.test of the animators' mean m_ij,
# chisq.test and binom.test over all comparisons), H2 (b_i: shapiro.test, t.test), H3 (lmer +
# lmerTest anova at the exact REML optimum, aov when balanced, shapiro.test of the residuals,
# chisq.test of the take x preference table). One-tailed tests use alternative = "greater",
# chance 0.5 and 0.125, conf.level 0.95 (the defaults of StudyAnalysisOptions).
script_dir <- local({
  file_arg <- grep("^--file=", commandArgs(FALSE), value = TRUE)
  dirname(normalizePath(sub("^--file=", "", file_arg[1])))
})
source(file.path(script_dir, "r_oracle.R"))
args <- commandArgs(trailingOnly = TRUE)
dir <- args[1]
output <- args[2]

rankings <- read.csv(file.path(dir, "rankings.csv"), stringsAsFactors = FALSE, comment.char = "#")
comparisons <- read.csv(file.path(dir, "comparisons.csv"), stringsAsFactors = FALSE,
                        comment.char = "#")
htest <- function(res) {
  list(statistic = num(res$statistic), parameter = if (is.null(res$parameter)) NULL else
       num(res$parameter), p_value = num(res$p.value),
       conf_int = if (is.null(res$conf.int)) NULL else vec(res$conf.int),
       estimate = if (is.null(res$estimate)) NULL else num(res$estimate))
}

# Friedman: animators x items (items sorted by name, animators sorted).
y <- with(rankings, tapply(rank, list(animator, item), identity))
friedman <- htest(friedman.test(y))

# m_ij, sorted by animator and take.
cells <- aggregate(montage_preferred ~ animator + take, data = comparisons,
                   FUN = function(v) c(n = length(v), wins = sum(v)))
cells <- data.frame(animator = cells$animator, take = cells$take,
                    n = cells$montage_preferred[, "n"], wins = cells$montage_preferred[, "wins"])
cells <- cells[order(cells$animator, cells$take), ]
cells$m <- cells$wins / cells$n
k <- max(cells$take)

animator_means <- tapply(cells$m, cells$animator, mean)
h1_t <- htest(t.test(animator_means, mu = 0.5, alternative = "greater"))
wins <- sum(comparisons$montage_preferred)
total <- nrow(comparisons)
h1_chisq <- htest(chisq.test(c(wins, total - wins), p = c(0.5, 0.5)))
h1_binom <- htest(binom.test(wins, total, 0.5, alternative = "greater"))

complete <- names(which(table(cells$animator) == k))
b <- tapply(cells$m[cells$animator %in% complete], cells$animator[cells$animator %in% complete],
            prod)
h2_shapiro <- htest(shapiro.test(b))
h2_t <- htest(t.test(b, mu = 0.125, alternative = "greater"))

d <- data.frame(animator = factor(cells$animator), take = factor(cells$take), y = cells$m)
fit <- fit_refined(d)
balanced <- all(table(d$animator, d$take) == 1)
rm <- NULL
if (balanced) {
  within <- summary(aov(y ~ take + Error(animator / take), data = d))[["Error: animator:take"]][[1]]
  rm <- list(f = num(within[["F value"]][1]), num_df = num(within$Df[1]),
             den_df = num(within$Df[2]), p_value = num(within[["Pr(>F)"]][1]))
}
tab <- table(factor(comparisons$take, levels = 1:k),
             factor(comparisons$montage_preferred, levels = c(1, 0)))
h3_table <- htest(suppressWarnings(chisq.test(matrix(tab, nrow = k), correct = TRUE)))

writeLines(json_value(list(
  friedman = friedman,
  h1 = list(mean_m = mean(animator_means), sd_m = sd(animator_means), wins = wins,
            comparisons = total, t_test = h1_t, chi_squared = h1_chisq, binomial = h1_binom),
  h2 = list(b = vec(b), shapiro = h2_shapiro, t_test = h2_t),
  h3 = list(theta = num(getME(fit$m, "theta")), sigma = num(sigma(fit$m)),
            singular = fit$theta == 0, anova = anova_row(fit$m), rm_anova = rm,
            residuals = vec(residuals(fit$m)),
            residual_shapiro = htest(shapiro.test(residuals(fit$m))), take_table = h3_table))),
  output)
