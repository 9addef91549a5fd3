/*---------------------------------------------------------------------------*\
  =========                 |
  \\      /  F ield         | bsplineMorph: multilevel B-spline mesh morphing
   \\    /   O peration     |
    \\  /    A nd           | Copyright (C) 2026 bsplineMorph developers
     \\/     M anipulation  |
-------------------------------------------------------------------------------
License
    This file is part of bsplineMorph, built on OpenFOAM.

    bsplineMorph is free software: you can redistribute it and/or modify it
    under the terms of the GNU General Public License as published by the
    Free Software Foundation, either version 3 of the License, or (at your
    option) any later version. See <http://www.gnu.org/licenses/>.

\*---------------------------------------------------------------------------*/

#include "PstreamCommunicator.H"
#include "Pstream.H"
#include "PstreamBuffers.H"
#include "UIPstream.H"
#include "UOPstream.H"

// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace
{
    Foam::List<char> toList(const mba::bytes& b)
    {
        Foam::List<char> l(b.size());
        std::copy(b.begin(), b.end(), l.begin());
        return l;
    }

    mba::bytes fromList(const Foam::UList<char>& l)
    {
        return mba::bytes(l.begin(), l.end());
    }

    //- The tag of the point-to-point messages whose sizes both sides know
    //  (exchangeInPlace, sendReceiveBytes): none of OpenFOAM's
    const int pointToPointTag = 28002;

    //- Post a non-blocking read of recv from rank from (nothing when empty)
    void postRead(const int from, const mba::byteRange& recv)
    {
        if (recv.size > 0)
        {
            Foam::UIPstream::read
            (
                Foam::Pstream::commsTypes::nonBlocking,
                from,
                recv.data,
                std::streamsize(recv.size),
                pointToPointTag
            );
        }
    }

    //- Post a non-blocking write of send to rank to (nothing when empty)
    void postWrite(const int to, const mba::constByteRange& send)
    {
        if (send.size > 0)
        {
            Foam::UOPstream::write
            (
                Foam::Pstream::commsTypes::nonBlocking,
                to,
                send.data,
                std::streamsize(send.size),
                pointToPointTag
            );
        }
    }
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

int Foam::PstreamCommunicator::rank() const
{
    return Pstream::parRun() ? Pstream::myProcNo() : 0;
}


int Foam::PstreamCommunicator::size() const
{
    return Pstream::parRun() ? Pstream::nProcs() : 1;
}


std::vector<mba::bytes> Foam::PstreamCommunicator::allGatherBytes
(
    const mba::bytes& mine
) const
{
    if (!Pstream::parRun())
    {
        return {mine};
    }
    List<List<char>> all(Pstream::nProcs());
    all[Pstream::myProcNo()] = toList(mine);
    Pstream::gatherList(all);
    Pstream::scatterList(all);

    std::vector<mba::bytes> out(all.size());
    forAll(all, proci)
    {
        out[proci] = fromList(all[proci]);
    }
    return out;
}


std::vector<mba::bytes> Foam::PstreamCommunicator::exchangeBytes
(
    const std::vector<mba::bytes>& send
) const
{
    const label nProcs = size();
    std::vector<mba::bytes> got(nProcs);
    const label me = rank();
    got[me] = send[me];
    if (!Pstream::parRun())
    {
        return got;
    }

    PstreamBuffers pBufs(Pstream::commsTypes::nonBlocking);
    for (label proci = 0; proci < nProcs; ++proci)
    {
        if (proci != me && !send[proci].empty())
        {
            UOPstream os(proci, pBufs);
            os << toList(send[proci]);
        }
    }
    labelList recvSizes;
    pBufs.finishedSends(recvSizes);

    for (label proci = 0; proci < nProcs; ++proci)
    {
        if (proci != me && recvSizes[proci] > 0)
        {
            UIPstream is(proci, pBufs);
            List<char> l(is);
            got[proci] = fromList(l);
        }
    }
    return got;
}


void Foam::PstreamCommunicator::exchangeInPlace
(
    const std::vector<mba::constByteRange>& send,
    const std::vector<mba::byteRange>& recv
) const
{
    if (!Pstream::parRun())
    {
        return;
    }
    // Every read posted before any write, then all waited for: only the
    // ranks with something to say talk, and no sizes travel
    const label start = UPstream::nRequests();
    const int me = rank();
    for (int proci = 0; proci < size(); ++proci)
    {
        if (proci != me) postRead(proci, recv[proci]);
    }
    for (int proci = 0; proci < size(); ++proci)
    {
        if (proci != me) postWrite(proci, send[proci]);
    }
    UPstream::waitRequests(start);
}


void Foam::PstreamCommunicator::sendReceiveBytes
(
    int to,
    mba::constByteRange send,
    int from,
    mba::byteRange recv
) const
{
    if (!Pstream::parRun())
    {
        return;
    }
    const label start = UPstream::nRequests();
    if (from >= 0) postRead(from, recv);
    if (to >= 0) postWrite(to, send);
    UPstream::waitRequests(start);
}


// ************************************************************************* //
