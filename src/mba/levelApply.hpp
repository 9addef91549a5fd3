// bsplineMorph: OpenFOAM-free multilevel B-spline core (internal header)
// The apply of one level, in every fit (the paper's Eq. 5-6): each control
// point c with residual r_c and stencil weights w proposes phi_c = w
// r_c/sum(w^2) to its 4^D nodes; this rank's partial sums delta = sum w^2
// phi_c are formed on its view, the other ranks' added (in rank order,
// their tiles or their ghosts' residuals received, directly or in chunks;
// or through a tree of the ranks), phi = delta/omega, and the level's
// values are subtracted from the residuals.
#ifndef MBA_LEVELAPPLY_HPP
#define MBA_LEVELAPPLY_HPP

#include "levelPlan.hpp"

namespace mba {

/// Applies levels to the residuals of this rank's control points, keeping
/// its work arrays from level to level and fit to fit
template <int D>
class levelApplier
{
    const communicator& comm_;              ///< the ranks
    const domain<D>& dom_;                  ///< the lattices' domain (for the ghosts' coordinates)
    const controlPoints<D>& ctrl_;          ///< this rank's control points
    std::vector<stencil<D>> stencils_;      ///< the control points' stencils at the current level, in order
    std::vector<stencil<D>> cubedStencils_; ///< the same with their weights cubed (for the scatter)
    std::vector<double> scaledResiduals_;   ///< r/sum(w^2) per point x component (levels not separated)
    std::vector<double> levelValues_;       ///< the current level's values at the control points, in order
    std::vector<double> setAside_;          ///< own partial sums of the tiles shared with lower ranks
    std::vector<double> chunkSum_;          ///< one chunk's sum (chunked exchange), a round's values (tree)
    std::vector<double> treeSums_;          ///< the level's tiles of all ranks (tree exchange)
    std::vector<std::vector<double>> send_, recv_; ///< per rank: what goes there, what comes from there
    std::vector<std::vector<double>> ghostSums_;   ///< per rank: its partial sums formed from its ghosts
    std::vector<double> ghostResiduals_;           ///< a rank's ghosts' r/sum(w^2)

    void clearLattice(levelPlan<D>& L) const;
    void computeStencils(const levelPlan<D>& L);
    void scaleResiduals(std::vector<double>& rr, const std::vector<double>& residuals) const;
    void scatterOwn(levelPlan<D>& L, const std::vector<double>& rr) const;
    void exchangePartialSums(levelPlan<D>& L, const std::vector<double>& residuals);
    void ghostPartialSums(const levelPlan<D>& L, int r, const std::vector<double>& got, std::vector<double>& dl);
    void addInRankOrder(levelPlan<D>& L, const std::vector<const double*>& got);
    void exchangeChunks(levelPlan<D>& L);
    void exchangeInTree(levelPlan<D>& L);
    void divideByOmega(levelPlan<D>& L, std::int64_t first, std::int64_t n, const double* s) const;
    void keepLoneResiduals(levelPlan<D>& L, const std::vector<double>& rr) const;
    void subtractLevel(const levelPlan<D>& L, const std::vector<double>& rr, std::vector<double>& residuals);

public:
    /// The points and domain are kept by reference: they must outlive the object
    levelApplier(const communicator& comm, const domain<D>& dom, const controlPoints<D>& ctrl)
    :
        comm_(comm), dom_(dom), ctrl_(ctrl)
    {}

    /// Fits level L to the residuals (point x component) and subtracts the
    /// level's values from them. Collective.
    void apply(levelPlan<D>& L, std::vector<double>& residuals);

    /// Bytes of the work arrays that the plan's size counts (all but levelValues_)
    std::int64_t bytes() const;
};

/// Stores the coefficients that a separated level's apply left out (those
/// not read every fit: levelPlan::readEveryFit), from the last fit's scaled
/// residuals; nothing when they are stored already. For the const
/// evaluations that read the whole lattice.
template <int D>
void storeDeferredCoefficients(const levelPlan<D>& L, const controlPoints<D>& ctrl);

} // namespace mba
#endif
